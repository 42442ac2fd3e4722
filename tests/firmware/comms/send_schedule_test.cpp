// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/node/send_schedule.hpp"

#include <gtest/gtest.h>

namespace tensegrity::fw::comms {
namespace {

constexpr std::int64_t kMs = 1'000'000;

TEST(SendSchedule, TelemetryKeepsItsGridAndSkipsAheadWhenBehind) {
  SendSchedule s(10 * kMs, 200 * kMs, 200 * kMs);
  s.start(0);
  EXPECT_TRUE(s.telemetry_due(0));
  EXPECT_FALSE(s.telemetry_due(9 * kMs));
  EXPECT_TRUE(s.telemetry_due(13 * kMs));  // late: the next one stays on the grid (20 ms)
  EXPECT_TRUE(s.telemetry_due(20 * kMs));
  EXPECT_TRUE(s.telemetry_due(95 * kMs));  // fell behind: one period from now
  EXPECT_FALSE(s.telemetry_due(104 * kMs));
  EXPECT_TRUE(s.telemetry_due(105 * kMs));
}

TEST(SendSchedule, TimeSyncStartsWithABurst) {
  SendSchedule s(10 * kMs, 200 * kMs, 200 * kMs);
  s.start(0);
  std::int64_t t = 0;
  for (std::uint32_t i = 1; i < SendSchedule::kInitialSyncBurst; ++i) {
    ASSERT_TRUE(s.sync_due(t));
    EXPECT_EQ(s.sync_requests(), i);
    t += SendSchedule::kInitialSyncSpacingNs;
  }
  ASSERT_TRUE(s.sync_due(t));  // the burst's last: then the interval
  EXPECT_FALSE(s.sync_due(t + SendSchedule::kInitialSyncSpacingNs));
  EXPECT_TRUE(s.sync_due(t + 200 * kMs));
}

TEST(SendSchedule, ARestartSendsAtOnceAndTheUnsyncedReportWaits) {
  SendSchedule s(10 * kMs, 200 * kMs, 200 * kMs);
  s.start(0);
  EXPECT_TRUE(s.heartbeat_due(0));
  EXPECT_FALSE(s.heartbeat_due(100 * kMs));
  EXPECT_EQ(s.next_ns(), 0);  // telemetry and sync still due
  s.restart(150 * kMs);
  EXPECT_TRUE(s.heartbeat_due(150 * kMs));
  EXPECT_FALSE(s.unsynced_report_due(SendSchedule::kUnsyncedReportNs - 1));
  EXPECT_TRUE(s.unsynced_report_due(SendSchedule::kUnsyncedReportNs));
  EXPECT_FALSE(s.unsynced_report_due(SendSchedule::kUnsyncedReportNs + 1));
}

}  // namespace
}  // namespace tensegrity::fw::comms
