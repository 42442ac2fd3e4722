// SPDX-License-Identifier: Apache-2.0
// The loop-progress watchdog and the injected link faults, with fake time.
#include "firmware/comms/node/loop_watch.hpp"

#include <gtest/gtest.h>

namespace tensegrity::fw::comms {
namespace {

constexpr std::int64_t kMs = 1'000'000;

TEST(LoopWatch, AliveWithoutAWatchdogAndBeforeTheLoopsFirstPass) {
  const NodeLog log{0, false};
  LoopWatch none(nullptr, 0.5, log);
  EXPECT_TRUE(none.alive(1'000'000 * kMs));
  std::atomic<std::uint64_t> progress{0};
  LoopWatch w(&progress, 0.5, log);
  w.start(0);
  EXPECT_TRUE(w.alive(10'000 * kMs)) << "the node starts before its loop";
}

TEST(LoopWatch, AStandingCounterIsAStallUntilItMovesAgain) {
  const NodeLog log{0, false};
  std::atomic<std::uint64_t> progress{1};
  LoopWatch w(&progress, 0.5, log);
  w.start(0);
  EXPECT_TRUE(w.alive(100 * kMs));  // moved at 100 ms
  EXPECT_TRUE(w.alive(600 * kMs));
  EXPECT_FALSE(w.alive(600 * kMs + 1));
  EXPECT_TRUE(w.stalled());
  EXPECT_FALSE(w.alive(900 * kMs));
  EXPECT_EQ(w.stalls(), 1U);
  progress = 2;
  EXPECT_TRUE(w.alive(1000 * kMs));
  EXPECT_FALSE(w.stalled());
  EXPECT_EQ(w.stalls(), 1U);
}

TEST(LinkFaultWatch, CountsCutsAndAsksEachMuteOnce) {
  const NodeLog log{0, false};
  std::atomic<bool> cut{false};
  std::atomic<std::uint32_t> mutes{0};
  LinkFaultWatch w(&cut, &mutes, log);
  EXPECT_FALSE(w.poll());
  cut = true;
  w.poll();
  w.poll();
  EXPECT_EQ(w.cuts(), 1U);
  cut = false;
  w.poll();
  cut = true;
  w.poll();
  EXPECT_EQ(w.cuts(), 2U);
  mutes = 1;
  EXPECT_TRUE(w.poll());
  EXPECT_FALSE(w.poll());
  mutes = 2;
  EXPECT_TRUE(w.poll());
  LinkFaultWatch none(nullptr, nullptr, log);
  EXPECT_FALSE(none.poll());
}

}  // namespace
}  // namespace tensegrity::fw::comms
