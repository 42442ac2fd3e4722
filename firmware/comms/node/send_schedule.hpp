// SPDX-License-Identifier: Apache-2.0
// When the node thread sends what it sends on its own: telemetry, its heartbeat,
// time-sync requests (a quick burst first, then every time_sync_interval_s) and,
// while unsynchronized, the line saying why. Plain time arithmetic, node clock.
#pragma once

#include <cstdint>

namespace tensegrity::fw::comms {

class SendSchedule {
 public:
  static constexpr std::uint32_t kInitialSyncBurst = 8;
  static constexpr std::int64_t kInitialSyncSpacingNs = 25'000'000;
  static constexpr std::int64_t kUnsyncedReportNs = 5'000'000'000;

  // Periods in ns (> 0; the node's config is validated before).
  SendSchedule(std::int64_t telemetry_period_ns, std::int64_t heartbeat_period_ns, std::int64_t sync_interval_ns)
      : telemetry_period_ns_(telemetry_period_ns),
        heartbeat_period_ns_(heartbeat_period_ns),
        sync_interval_ns_(sync_interval_ns) {}

  // Everything due at once; the first unsynced report kUnsyncedReportNs later.
  void start(std::int64_t now_ns);
  // A new participant: telemetry, heartbeat and a time-sync request due at once.
  void restart(std::int64_t now_ns) { next_telemetry_ns_ = next_heartbeat_ns_ = next_sync_ns_ = now_ns; }

  // Each true at most once per due time, and then the next one is set.
  bool telemetry_due(std::int64_t now_ns);
  bool heartbeat_due(std::int64_t now_ns);
  bool sync_due(std::int64_t now_ns);
  bool unsynced_report_due(std::int64_t now_ns);

  std::uint32_t sync_requests() const { return sync_requests_; }  // the last request's sequence number
  std::int64_t next_ns() const;                                   // the earliest of telemetry, heartbeat and sync

 private:
  std::int64_t telemetry_period_ns_;
  std::int64_t heartbeat_period_ns_;
  std::int64_t sync_interval_ns_;
  std::int64_t next_telemetry_ns_ = 0;
  std::int64_t next_heartbeat_ns_ = 0;
  std::int64_t next_sync_ns_ = 0;
  std::int64_t next_unsynced_report_ns_ = 0;
  std::uint32_t sync_requests_ = 0;
};

}  // namespace tensegrity::fw::comms
