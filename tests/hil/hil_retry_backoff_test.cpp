// SPDX-License-Identifier: Apache-2.0
// The supervisor's pacing of an order a restarted end cap refuses: the wait doubles
// to its cap, the log keeps a handful of lines, and a new restart starts afresh.
#include "hil/retry_backoff.hpp"

#include <gtest/gtest.h>

#include <cstdint>

namespace tensegrity::hil {
namespace {

constexpr std::int64_t kMs = 1'000'000;

TEST(RetryBackoff, WaitDoublesToItsCap) {
  RetryBackoff r(250 * kMs, 2000 * kMs);
  r.follow(1);
  EXPECT_TRUE(r.due(0));
  std::int64_t now = 10 * kMs;
  const std::int64_t expected_ms[] = {250, 500, 1000, 2000, 2000, 2000};
  for (const std::int64_t w : expected_ms) {
    r.refused(now, "clock not synchronized");
    EXPECT_EQ(r.wait_ns(), w * kMs);
    EXPECT_FALSE(r.due(now + w * kMs - 1));
    EXPECT_TRUE(r.due(now + w * kMs));
    now += w * kMs;
  }
  EXPECT_EQ(r.refusals(), 6);
  EXPECT_EQ(r.last_reason(), "clock not synchronized");
}

// At the supervisor's 50 Hz an end cap refusing for a minute was 3000 tries and 3000
// lines; paced, it is a few tries and fewer lines.
TEST(RetryBackoff, AMinuteOfRefusalsIsAFewTriesAndFewerLines) {
  RetryBackoff r;
  r.follow(7);
  int tries = 0;
  int lines = 0;
  for (std::int64_t now = 0; now < 60'000 * kMs; now += 20 * kMs) {  // the supervisor's tick
    if (!r.due(now)) continue;
    ++tries;
    if (r.refused(now, "no answer")) ++lines;
  }
  EXPECT_EQ(tries, r.refusals());
  EXPECT_EQ(tries, 33);  // at 0, 0.26, 0.76, 1.76 s (on the tick after each wait), then every 2 s to 59.76 s
  EXPECT_EQ(lines, 6);   // refusals 1, 2, 4, 8, 16, 32
}

TEST(RetryBackoff, ANewRestartStartsAfresh) {
  RetryBackoff r;
  r.follow(100);
  r.refused(0, "mailbox full");
  r.refused(RetryBackoff::kFirstWaitNs, "mailbox full");
  r.follow(100);  // the same restart: nothing forgotten
  EXPECT_EQ(r.refusals(), 2);
  EXPECT_FALSE(r.due(RetryBackoff::kFirstWaitNs + 1));
  r.follow(200);  // killed and started again
  EXPECT_EQ(r.refusals(), 0);
  EXPECT_EQ(r.last_reason(), "");
  EXPECT_TRUE(r.due(0));
  EXPECT_TRUE(r.refused(0, "stale"));  // its first refusal is logged again
}

// Thinning keeps a reason that changed: a start refused as stale, then unanswered.
TEST(RetryBackoff, AChangedReasonIsLogged) {
  RetryBackoff r(0, 0);
  r.follow(1);
  const bool expected[] = {true, true, false, true, false};  // 1st, 2nd, 4th
  for (const bool e : expected) EXPECT_EQ(r.refused(0, "stale"), e);
  EXPECT_TRUE(r.refused(0, "no acknowledgement"));   // the 6th, a new reason
  EXPECT_FALSE(r.refused(0, "no acknowledgement"));  // the 7th
  EXPECT_EQ(r.refusals(), 7);
  EXPECT_EQ(r.last_reason(), "no acknowledgement");
}

// Lockstep's recall stops an end cap that started on boot after an estop. recall()
// never asks due() (a stop must not wait); this pins that a zero wait, its
// backoff's, would not hold one back either, and thins the lines all the same.
TEST(RetryBackoff, AZeroWaitNeverHoldsAStopBack) {
  RetryBackoff r(0, 0);
  r.follow(1);
  int lines = 0;
  for (int i = 0; i < 100; ++i) {
    EXPECT_TRUE(r.due(i * 20 * kMs));
    if (r.refused(i * 20 * kMs, "mailbox full")) ++lines;
  }
  EXPECT_EQ(lines, 7);  // 1, 2, 4, ... 64
}

}  // namespace
}  // namespace tensegrity::hil
