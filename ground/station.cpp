// SPDX-License-Identifier: Apache-2.0
#include "ground/station.hpp"
#include "ground/station_samples.hpp"

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>

#include "msgs/dds.hpp"
#include "msgs/endcap_writers.hpp"
#include "msgs/matched_readers.hpp"
#include "tensegrity_msgs/msg/CommandAckPubSubTypes.h"
#include "tensegrity_msgs/msg/CommandPubSubTypes.h"
#include "tensegrity_msgs/msg/HeartbeatPubSubTypes.h"
#include "tensegrity_msgs/msg/PolicyAckPubSubTypes.h"
#include "tensegrity_msgs/msg/PolicyTablePubSubTypes.h"
#include "tensegrity_msgs/msg/TelemetryPubSubTypes.h"
#include "tensegrity_msgs/msg/TimeSyncPubSubTypes.h"

namespace tensegrity::ground {

namespace dds = eprosima::fastdds::dds;

// One listener per reader; each takes its samples in the receive thread.
struct StationListeners {
  class Listener final : public dds::DataReaderListener {
   public:
    Listener(Station& station, void (*fn)(Station&, dds::DataReader*), const char* topic)
        : station_(station), fn_(fn), topic_(topic) {}
    void on_data_available(dds::DataReader* reader) override { fn_(station_, reader); }
    void on_requested_incompatible_qos(dds::DataReader*, const dds::RequestedIncompatibleQosStatus&) override {
      std::fprintf(stderr, "ground: incompatible QoS offered on %s\n", topic_);
    }

   private:
    Station& station_;
    void (*fn_)(Station&, dds::DataReader*);
    const char* topic_;
  };

  // True when the writer of `info` publishes for `endcap` (its partition, which the
  // permissions bind to its identity); else the sample is counted, said now and
  // then, and must be dropped: an end cap speaking for another.
  static bool vouched(Station& s, const dds::SampleInfo& info, int endcap, const char* what);
  static void policy_acks(Station& s, dds::DataReader* r);
  static void command_acks(Station& s, dds::DataReader* r);
  static void telemetry(Station& s, dds::DataReader* r);
  static void heartbeats(Station& s, dds::DataReader* r);
  static void time_sync(Station& s, dds::DataReader* r);
};

struct Station::Dds {
  // Declared first, destroyed last: the participant (deleted in close()) calls it.
  msgs::EndcapWriters writers;
  msgs::MatchedReaders policy_readers, command_readers;  // the writers' listeners
  dds::DomainParticipant* participant = nullptr;
  dds::Publisher* publisher = nullptr;
  dds::Subscriber* subscriber = nullptr;
  dds::DataWriter* policy = nullptr;
  dds::DataWriter* command = nullptr;
  dds::DataWriter* heartbeat = nullptr;
  dds::DataWriter* sync_reply = nullptr;
  std::vector<std::unique_ptr<StationListeners::Listener>> listeners;
  std::mutex write_mutex;  // the time-sync reply writer is used from the receive thread
  // Set (under write_mutex) before anything is deleted: a time-sync request being
  // answered meanwhile finishes first, a later one is not answered. Without it a
  // request arriving while a ground tool exited reached through a half-destroyed
  // object (seen: `tensegrity upload` ending with SIGSEGV after a good upload).
  bool closed = false;

  ~Dds() { close(); }
  void close() noexcept {
    {
      std::lock_guard lock(write_mutex);
      closed = true;
    }
    msgs::delete_participant(participant);
    participant = nullptr;
  }
  dds::DataWriter* writer(const msgs::TopicSpec& spec, dds::TypeSupport type,
                          dds::DataWriterListener* listener = nullptr) {
    return msgs::create_writer(*participant, *publisher, spec, type, listener);
  }
  void reader(Station& station, const msgs::TopicSpec& spec, dds::TypeSupport type,
              void (*fn)(Station&, dds::DataReader*)) {
    listeners.push_back(std::make_unique<StationListeners::Listener>(station, fn, spec.name));
    msgs::create_reader(*participant, *subscriber, spec, type, listeners.back().get());
  }
};

std::int64_t Station::now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

Station::Station(const StationOptions& options) : options_(options), dds_(std::make_unique<Dds>()) {
  Dds& d = *dds_;
  d.participant = msgs::create_participant(options.domain, options.name, {}, options.enclave_dir, &d.writers);
  d.publisher = d.participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  // Every end cap's reports, each from its own partition (msgs/endcap_writers.hpp).
  d.subscriber = d.participant->create_subscriber(msgs::endcap_reports_qos());
  if (d.publisher == nullptr || d.subscriber == nullptr) throw msgs::DdsError("cannot create publisher/subscriber");
  d.policy = d.writer(msgs::kPolicyTableTopic, dds::TypeSupport(new msg::PolicyTable_PubSubType()), &d.policy_readers);
  d.command = d.writer(msgs::kCommandTopic, dds::TypeSupport(new msg::Command_PubSubType()), &d.command_readers);
  d.heartbeat = d.writer(msgs::kHostHeartbeatTopic, dds::TypeSupport(new msg::Heartbeat_PubSubType()));
  d.sync_reply = d.writer(msgs::kTimeSyncReplyTopic, dds::TypeSupport(new msg::TimeSyncReply_PubSubType()));
  d.reader(*this, msgs::kPolicyAckTopic, dds::TypeSupport(new msg::PolicyAck_PubSubType()),
           &StationListeners::policy_acks);
  d.reader(*this, msgs::kCommandAckTopic, dds::TypeSupport(new msg::CommandAck_PubSubType()),
           &StationListeners::command_acks);
  d.reader(*this, msgs::kTelemetryTopic, dds::TypeSupport(new msg::Telemetry_PubSubType()),
           &StationListeners::telemetry);
  d.reader(*this, msgs::kEndcapHeartbeatTopic, dds::TypeSupport(new msg::Heartbeat_PubSubType()),
           &StationListeners::heartbeats);
  if (options.serve_time) {
    d.reader(*this, msgs::kTimeSyncRequestTopic, dds::TypeSupport(new msg::TimeSyncRequest_PubSubType()),
             &StationListeners::time_sync);
  }
  if (options.publish_heartbeat) heartbeat_thread_ = std::make_unique<std::thread>([this] { heartbeat_loop(); });
}

Station::~Station() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  stop_cv_.notify_all();
  if (heartbeat_thread_) heartbeat_thread_->join();
  // Entities deleted while dds_ still points at them (reset() would null it first,
  // under the feet of the receive thread's callbacks).
  dds_->close();
  dds_.reset();
}

void Station::heartbeat_loop() {
  const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / options_.heartbeat_rate_hz));
  std::uint32_t seq = 0;
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    lock.unlock();
    msg::Heartbeat_ hb;
    hb.format_version(msgs::kFormatVersion);
    hb.source(-1);
    hb.seq(++seq);
    const std::int64_t now = now_ns();
    hb.time_ns(now);
    hb.heard_endcaps(heard(now, kHeardFreshS));
    dds_->heartbeat->write(&hb);
    lock.lock();
    stop_cv_.wait_for(lock, period, [this] { return stopping_; });
  }
}

void Station::write_policy(const msg::PolicyTable_& table) {
  msg::PolicyTable_ copy = table;
  dds_->policy->write(&copy);
}

void Station::write_command(const msg::Command_& command) {
  msg::Command_ copy = command;
  dds_->command->write(&copy);
}

std::vector<msg::PolicyAck_> Station::take_policy_acks() {
  std::lock_guard lock(mutex_);
  return std::exchange(policy_acks_, {});
}

std::vector<msg::CommandAck_> Station::take_command_acks() {
  std::lock_guard lock(mutex_);
  return std::exchange(command_acks_, {});
}

void Station::wait_for_policy_acks(std::int64_t deadline_ns) {
  std::unique_lock lock(mutex_);
  const std::int64_t wait = deadline_ns - now_ns();
  if (wait <= 0) return;
  changed_.wait_for(lock, std::chrono::nanoseconds(wait), [this] { return !policy_acks_.empty(); });
}

void Station::wait_for_command_acks(std::int64_t deadline_ns) {
  std::unique_lock lock(mutex_);
  const std::int64_t wait = deadline_ns - now_ns();
  if (wait <= 0) return;
  changed_.wait_for(lock, std::chrono::nanoseconds(wait), [this] { return !command_acks_.empty(); });
}

std::array<EndcapStatus, kEndcapCount> Station::snapshot() const {
  const std::uint16_t reach = reached();  // its own locks: taken before this station's
  std::lock_guard lock(mutex_);
  std::array<EndcapStatus, kEndcapCount> out = status_;
  for (int e = 0; e < kEndcapCount; ++e) out[static_cast<std::size_t>(e)].reached = (reach & (1U << e)) != 0;
  return out;
}

std::uint16_t Station::heard(std::int64_t now_ns, double fresh_s) const {
  const auto fresh_ns = static_cast<std::int64_t>(fresh_s * 1e9);
  std::lock_guard lock(mutex_);
  std::uint16_t mask = 0;
  for (int e = 0; e < kEndcapCount; ++e) {
    const EndcapStatus& s = status_[static_cast<std::size_t>(e)];
    if (s.seen && now_ns - s.heartbeat_host_ns <= fresh_ns) mask = static_cast<std::uint16_t>(mask | (1U << e));
  }
  return mask;
}

std::uint16_t Station::reached() const {
  const Dds& d = *dds_;
  return static_cast<std::uint16_t>(d.writers.endcaps_of_participants(
      [&d](const auto& p) { return d.policy_readers.reaches(p) && d.command_readers.reaches(p); }));
}

bool Station::wait_for_endcaps(std::uint16_t mask, bool synced, std::int64_t deadline_ns) const {
  for (;;) {
    const std::uint16_t reach = reached();  // its own locks: taken before this station's
    std::unique_lock lock(mutex_);
    bool ready = (reach & mask) == mask;
    for (int i = 0; i < kEndcapCount && ready; ++i) {
      if ((mask & (1U << i)) == 0) continue;
      ready = status_[i].seen && (!synced || status_[i].heartbeat.clock_synced());
    }
    if (ready) return true;
    const std::int64_t wait = deadline_ns - now_ns();
    if (wait <= 0) return false;
    // Matching is not signalled here: looked at again every 20 ms.
    changed_.wait_for(lock, std::chrono::nanoseconds(std::min<std::int64_t>(wait, 20'000'000)));
  }
}

void Station::on_telemetry(std::function<void(const msg::Telemetry_&, std::int64_t)> callback) {
  std::lock_guard lock(mutex_);
  telemetry_callback_ = std::move(callback);
}

std::uint64_t Station::impostor_samples() const {
  std::lock_guard lock(mutex_);
  return impostor_samples_;
}

std::uint64_t Station::time_sync_replies() const {
  std::lock_guard lock(mutex_);
  return sync_replies_;
}

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
