// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/node/send_schedule.hpp"

#include <algorithm>

namespace tensegrity::fw::comms {

void SendSchedule::start(std::int64_t now_ns) {
  restart(now_ns);
  next_unsynced_report_ns_ = now_ns + kUnsyncedReportNs;
}

bool SendSchedule::telemetry_due(std::int64_t now_ns) {
  if (now_ns < next_telemetry_ns_) return false;
  next_telemetry_ns_ += telemetry_period_ns_;
  if (next_telemetry_ns_ <= now_ns) next_telemetry_ns_ = now_ns + telemetry_period_ns_;  // fell behind
  return true;
}

bool SendSchedule::heartbeat_due(std::int64_t now_ns) {
  if (now_ns < next_heartbeat_ns_) return false;
  next_heartbeat_ns_ = std::max(next_heartbeat_ns_ + heartbeat_period_ns_, now_ns);
  return true;
}

bool SendSchedule::sync_due(std::int64_t now_ns) {
  if (now_ns < next_sync_ns_) return false;
  ++sync_requests_;
  next_sync_ns_ = now_ns + (sync_requests_ < kInitialSyncBurst ? kInitialSyncSpacingNs : sync_interval_ns_);
  return true;
}

bool SendSchedule::unsynced_report_due(std::int64_t now_ns) {
  if (now_ns < next_unsynced_report_ns_) return false;
  next_unsynced_report_ns_ = now_ns + kUnsyncedReportNs;
  return true;
}

std::int64_t SendSchedule::next_ns() const { return std::min({next_telemetry_ns_, next_heartbeat_ns_, next_sync_ns_}); }

}  // namespace tensegrity::fw::comms
