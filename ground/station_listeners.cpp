// SPDX-License-Identifier: Apache-2.0
// What arrives from the end caps, in the receive thread: each sample checked (its
// writer's partition vouches for the end cap it names, this format version) before
// the station keeps it.
#include "ground/station_dds.hpp"
#include "ground/station_samples.hpp"
#include "tensegrity_msgs/msg/CommandAckPubSubTypes.h"
#include "tensegrity_msgs/msg/HeartbeatPubSubTypes.h"
#include "tensegrity_msgs/msg/PolicyAckPubSubTypes.h"
#include "tensegrity_msgs/msg/TelemetryPubSubTypes.h"
#include "tensegrity_msgs/msg/TimeSyncPubSubTypes.h"

namespace tensegrity::ground {

bool StationListeners::vouched(Station& s, const dds::SampleInfo& info, int endcap, const char* what) {
  const int writer_endcap = s.dds_->writers.endcap_of(info);
  if (writer_endcap == endcap && valid_endcap(endcap)) return true;
  std::lock_guard lock(s.mutex_);
  if (s.impostor_samples_++ % 1000 == 0) {
    std::fprintf(stderr, "ground: REFUSED %s claiming end cap %d from a writer of %s%d (not its partition)\n", what,
                 endcap, writer_endcap < 0 ? "no end cap, " : "end cap ", writer_endcap);
  }
  return false;
}

void StationListeners::policy_acks(Station& s, dds::DataReader* r) {
  msg::PolicyAck_ ack;
  dds::SampleInfo info;
  while (r->take_next_sample(&ack, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data || !vouched(s, info, ack.endcap_id(), "policy ack")) continue;
    std::lock_guard lock(s.mutex_);
    if (check_ack(ack.format_version()) != SampleVerdict::taken) {
      std::fprintf(stderr, "ground: REFUSED policy ack from end cap %d: format version %u, we speak %u\n",
                   int{ack.endcap_id()}, unsigned{ack.format_version()}, unsigned{msgs::kFormatVersion});
      continue;
    }
    if (s.policy_acks_.size() >= Station::kMaxPendingAcks) s.policy_acks_.erase(s.policy_acks_.begin());
    s.policy_acks_.push_back(ack);
    s.changed_.notify_all();
  }
}

void StationListeners::command_acks(Station& s, dds::DataReader* r) {
  msg::CommandAck_ ack;
  dds::SampleInfo info;
  while (r->take_next_sample(&ack, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data || !vouched(s, info, ack.endcap_id(), "command ack")) continue;
    std::lock_guard lock(s.mutex_);
    if (check_ack(ack.format_version()) != SampleVerdict::taken) {
      std::fprintf(stderr, "ground: REFUSED command ack from end cap %d: format version %u, we speak %u\n",
                   int{ack.endcap_id()}, unsigned{ack.format_version()}, unsigned{msgs::kFormatVersion});
      continue;
    }
    if (s.command_acks_.size() >= Station::kMaxPendingAcks) s.command_acks_.erase(s.command_acks_.begin());
    s.command_acks_.push_back(ack);
    s.changed_.notify_all();
  }
}

void StationListeners::telemetry(Station& s, dds::DataReader* r) {
  msg::Telemetry_ t;
  dds::SampleInfo info;
  while (r->take_next_sample(&t, &info) == ReturnCode_t::RETCODE_OK) {
    const std::int64_t now = Station::now_ns();
    if (!info.valid_data || !vouched(s, info, t.endcap_id(), "telemetry")) continue;
    std::function<void(const msg::Telemetry_&, std::int64_t)> callback;
    {
      std::lock_guard lock(s.mutex_);
      EndcapStatus& e = s.status_[static_cast<std::size_t>(t.endcap_id())];
      if (take_telemetry(e, t, now) != SampleVerdict::taken) {
        if (e.refused % 1000 == 1) {
          std::fprintf(stderr, "ground: REFUSED telemetry from end cap %d: format version %u, we speak %u\n",
                       int{t.endcap_id()}, unsigned{t.format_version()}, unsigned{msgs::kFormatVersion});
        }
        continue;
      }
      callback = s.telemetry_callback_;
    }
    if (callback) callback(t, now);
  }
}

void Station::note_estops(int endcap, const fw::comms::EstopCount& heard) {
  if (endcap < 0 || endcap >= kEndcapCount) return;
  std::lock_guard lock(mutex_);
  merge_estops(status_[static_cast<std::size_t>(endcap)], heard);
}

void StationListeners::heartbeats(Station& s, dds::DataReader* r) {
  msg::Heartbeat_ hb;
  dds::SampleInfo info;
  while (r->take_next_sample(&hb, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data || !vouched(s, info, hb.source(), "heartbeat")) continue;
    std::lock_guard lock(s.mutex_);
    EndcapStatus& e = s.status_[static_cast<std::size_t>(hb.source())];
    const SampleVerdict verdict = take_heartbeat(e, hb, Station::now_ns());
    if (verdict == SampleVerdict::wrong_format && e.refused % 100 == 1) {
      std::fprintf(stderr, "ground: REFUSED heartbeat from end cap %d: format version %u, we speak %u\n",
                   int{hb.source()}, unsigned{hb.format_version()}, unsigned{msgs::kFormatVersion});
    }
    if (verdict == SampleVerdict::taken) s.changed_.notify_all();
  }
}

void StationListeners::time_sync(Station& s, dds::DataReader* r) {
  msg::TimeSyncRequest_ req;
  dds::SampleInfo info;
  while (r->take_next_sample(&req, &info) == ReturnCode_t::RETCODE_OK) {
    const std::int64_t t2 = Station::now_ns();
    if (!info.valid_data || req.format_version() != msgs::kFormatVersion) continue;
    if (!vouched(s, info, req.endcap_id(), "time-sync request")) continue;
    msg::TimeSyncReply_ reply;
    reply.format_version(msgs::kFormatVersion);
    reply.endcap_id(req.endcap_id());
    reply.seq(req.seq());
    reply.nonce(req.nonce());
    reply.t1_ns(req.t1_ns());
    reply.t2_ns(t2);
    std::lock_guard write_lock(s.dds_->write_mutex);
    if (s.dds_->closed) return;
    reply.t3_ns(Station::now_ns());
    s.dds_->sync_reply->write(&reply);
    std::lock_guard lock(s.mutex_);
    ++s.sync_replies_;
  }
}

}  // namespace tensegrity::ground
