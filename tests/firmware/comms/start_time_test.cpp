// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/logic/start_time.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "firmware/comms/wire/wire_time.hpp"

namespace tensegrity::fw::comms {
namespace {

TEST(StartTime, FreeRunningMapsHostTimeThroughTheOffsetAndTheLoopsLastCycle) {
  const StartTimeMapper mapper;
  // Node clock 1000 s at the loop's last publish, loop time 7 s; host = node + 50 s.
  const LoopClockPoint last{7'000'000'000, 1'000'000'000'000};
  const std::int64_t offset = 50'000'000'000;
  // Host 1052 s = node 1002 s = 2 s after the last cycle: loop time 9 s.
  EXPECT_EQ(mapper.map(1'052'000'000'000, offset, last), 9'000'000'000);
  // In the past: a loop time before the last cycle (the loop starts at once, that far along).
  EXPECT_EQ(mapper.map(1'049'000'000'000, offset, last), 6'000'000'000);
}

TEST(StartTime, LockstepRoundsToWholeGridStepsAfterTheLastCycle) {
  const StartTimeMapper mapper(200'000'000);
  const LoopClockPoint last{5'000'000'000, 100'000'000'000};
  auto at = [&](std::int64_t since_ns) { return mapper.map(100'000'000'000 + since_ns, 0, last); };
  EXPECT_EQ(at(400'000'000), 5'400'000'000);
  EXPECT_EQ(at(400'000'000 + 99'999'999), 5'400'000'000);  // mapping error under half a step
  EXPECT_EQ(at(400'000'000 - 99'999'999), 5'400'000'000);
  EXPECT_EQ(at(500'000'000), 5'600'000'000);   // half a step rounds away from zero
  EXPECT_EQ(at(-300'000'000), 4'600'000'000);  // before the last cycle: away from zero too
}

TEST(StartTime, RoundDivIsSymmetricAndDoesNotOverflow) {
  EXPECT_EQ(round_div(5, 10), 1);
  EXPECT_EQ(round_div(-5, 10), -1);
  EXPECT_EQ(round_div(4, 10), 0);
  EXPECT_EQ(round_div(-4, 10), 0);
  EXPECT_EQ(round_div(std::numeric_limits<std::int64_t>::max(), 3), std::numeric_limits<std::int64_t>::max() / 3);
  EXPECT_EQ(round_div(std::numeric_limits<std::int64_t>::min(), 2), std::numeric_limits<std::int64_t>::min() / 2);
}

TEST(StartTime, RefusesTimesOutsideTheWireRangeAndResultsThatWouldOverflow) {
  const StartTimeMapper mapper;
  const StartTimeMapper grid(200'000'000);
  const LoopClockPoint last{0, 0};
  constexpr auto kMin = std::numeric_limits<std::int64_t>::min();
  constexpr auto kMax = std::numeric_limits<std::int64_t>::max();
  EXPECT_FALSE(mapper.map(-1, 0, last));
  EXPECT_FALSE(mapper.map(kMax, 0, last));
  EXPECT_FALSE(mapper.map(0, kMin, last));
  EXPECT_FALSE(grid.map(kMaxWireTimeNs, 0, LoopClockPoint{kMax, kMin + 1}));
  EXPECT_FALSE(mapper.map(kMaxWireTimeNs, -kMaxWireTimeNs, LoopClockPoint{kMax, 0}));
  EXPECT_TRUE(mapper.map(kMaxWireTimeNs, kMaxWireTimeNs, last));
}

}  // namespace
}  // namespace tensegrity::fw::comms
