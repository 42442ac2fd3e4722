// SPDX-License-Identifier: Apache-2.0
// Time-sync requests (node thread) and replies (Fast DDS's receive thread); the
// judging is TimeSyncClient's (time_sync_client.hpp).
#include "firmware/comms/node/endcap_node.hpp"
#include "firmware/comms/node/node_dds.hpp"
#include "tensegrity_msgs/msg/TimeSync.h"

namespace tensegrity::fw::comms {

namespace m = tensegrity_msgs::msg::dds_;

void EndcapNode::send_time_sync_request() {
  m::TimeSyncRequest_ req;
  req.format_version(msgs::kFormatVersion);
  req.endcap_id(static_cast<std::int16_t>(config_.endcap_id));
  req.seq(++sync_sequence_);
  {
    std::lock_guard lock(mutex_);
    const std::int64_t t1 = clock_.now_ns();  // as late as possible: the round trip starts here
    req.t1_ns(t1);
    req.nonce(sync_.start_request(t1));
  }
  dds_->sync_request->write(&req);
}

void EndcapNode::report_if_unsynced() {
  TimeSyncCounters c;
  {
    std::lock_guard lock(mutex_);
    if (sync_.estimator().synced()) return;
    c = sync_.counters();
  }
  using ull = unsigned long long;
  log("time sync: not synchronized after %u requests; replies accepted %llu, late or replayed %llu, implausible %llu "
      "(round trip > limit %llu, host hold > limit %llu), conflicting %llu",
      sync_sequence_, static_cast<ull>(c.accepted), static_cast<ull>(c.unknown_nonce), static_cast<ull>(c.implausible),
      static_cast<ull>(c.implausible_round_trip), static_cast<ull>(c.implausible_hold),
      static_cast<ull>(c.conflicting));
}

void EndcapNode::on_time_sync_reply(Dds& d) {
  std::lock_guard guard(d.callback_mutex);
  if (d.closed || d.sync_reply == nullptr) return;  // stopping, or still starting (taken next time)
  if (d.retiring) return;                           // its replies reach the new participant too: counted there once
  m::TimeSyncReply_ reply;
  dds::SampleInfo info;
  while (d.sync_reply->take_next_sample(&reply, &info) == ReturnCode_t::RETCODE_OK) {
    const std::int64_t t4 = clock_.now_ns();  // stamped before anything else
    if (!info.valid_data || reply.endcap_id() != config_.endcap_id) continue;
    if (reply.format_version() != msgs::kFormatVersion) continue;
    std::uint64_t refused = 0;
    std::uint64_t unknown = 0;
    {
      std::lock_guard lock(mutex_);
      const TimeSyncVerdict verdict = sync_.on_reply(reply.nonce(), reply.t2_ns(), reply.t3_ns(), t4);
      if (verdict == TimeSyncVerdict::implausible) refused = sync_.counters().implausible;
      if (verdict == TimeSyncVerdict::unknown_nonce) unknown = sync_.counters().unknown_nonce;
    }
    // Both say why an end cap stays unsynchronized ("see their logs").
    if (refused % 100 == 1)
      log("refused an implausible time-sync reply (%llu so far)", static_cast<unsigned long long>(refused));
    if (unknown % 100 == 1) {
      log("ignored a time-sync reply to no open request: late or replayed (%llu so far)",
          static_cast<unsigned long long>(unknown));
    }
  }
}

}  // namespace tensegrity::fw::comms
