// SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>

#include "firmware/comms/wire/clock_sync.hpp"

namespace tensegrity::fw::comms {
namespace {

// An exchange with the host `offset` ahead, `up`/`down` one-way delays and `hold`
// spent in the host between receive and reply.
void exchange(ClockSyncEstimator& est, std::int64_t t1, std::int64_t offset, std::int64_t up, std::int64_t down,
              std::int64_t hold = 1000) {
  const std::int64_t t2 = t1 + up + offset;
  const std::int64_t t3 = t2 + hold;
  const std::int64_t t4 = t3 - offset + down;
  ASSERT_TRUE(est.add(t1, t2, t3, t4));
}

TEST(ClockSync, SymmetricExchangeGivesTheExactOffset) {
  ClockSyncEstimator est;
  EXPECT_FALSE(est.synced());
  exchange(est, 1'000'000, 5'000'000'000, 40'000, 40'000);
  ASSERT_TRUE(est.synced());
  EXPECT_EQ(est.best().offset_ns, 5'000'000'000);
  EXPECT_EQ(est.best().round_trip_ns, 80'000);
  EXPECT_EQ(est.to_host_ns(10), 5'000'000'010);
  EXPECT_EQ(est.to_local_ns(5'000'000'010), 10);
}

TEST(ClockSync, KeepsTheSmallestRoundTripAndStaysWithinItsBound) {
  ClockSyncEstimator est;
  const std::int64_t offset = -3'000'000'000;
  exchange(est, 0, offset, 900'000, 50'000);          // queued on the way up: skewed
  exchange(est, 10'000'000, offset, 30'000, 35'000);  // the good one
  exchange(est, 20'000'000, offset, 50'000, 700'000);
  const ClockSample s = est.best();
  EXPECT_EQ(s.round_trip_ns, 65'000);
  EXPECT_LE(std::llabs(s.offset_ns - offset), s.round_trip_ns / 2);
}

TEST(ClockSync, OldSamplesLeaveTheWindow) {
  ClockSyncEstimator est;
  exchange(est, 0, 100, 1'000, 1'000);  // best round trip, then pushed out
  for (int i = 1; i <= static_cast<int>(ClockSyncEstimator::kWindow); ++i) {
    exchange(est, i * 1'000'000, 200, 5'000, 5'000);
  }
  EXPECT_EQ(est.best().offset_ns, 200);
  EXPECT_EQ(est.samples(), ClockSyncEstimator::kWindow);
}

TEST(ClockSync, RejectsImpossibleSamples) {
  ClockSyncEstimator est;
  EXPECT_FALSE(est.add(100, 50, 200, 120));  // host held it longer than the round trip
  EXPECT_FALSE(est.add(100, 0, 0, 90));      // answered before asked (local)
  EXPECT_FALSE(est.synced());
}

TEST(ClockSync, FarApartClocksDoNotOverflow) {
  ClockSyncEstimator est;
  const std::int64_t big = 4'000'000'000'000'000'000;  // ~127 years of ns
  exchange(est, 0, big, 1000, 1000, 0);
  EXPECT_EQ(est.best().offset_ns, big);
}

}  // namespace
}  // namespace tensegrity::fw::comms
