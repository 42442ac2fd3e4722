// SPDX-License-Identifier: Apache-2.0
// When the end cap makes a new participant, with fake time and host heartbeats.
#include "firmware/comms/node/rejoin_watch.hpp"

#include <gtest/gtest.h>

namespace tensegrity::fw::comms {
namespace {

constexpr std::int64_t kS = 1'000'000'000;
constexpr std::int64_t kMs = 1'000'000;
constexpr std::uint16_t kSelf = 1U << 0;
constexpr std::uint16_t kOthers = 0b1110;  // end caps 1..3
const RejoinWatch::Host kWatched{true, false, false};

class RejoinWatchTest : public ::testing::Test {
 protected:
  // Host heartbeats every 200 ms over [from, to) naming `mask`; polls after each.
  // Returns the first time a rejoin was asked for, or -1.
  std::int64_t hear(RejoinWatch& w, std::int64_t from, std::int64_t to, std::uint16_t mask,
                    const RejoinWatch::Host& host = kWatched) {
    for (std::int64_t t = from; t < to; t += 200 * kMs) {
      w.heard(mask, t, t == from && fresh_, true);
      if (w.poll(t, host, overlapping_).rejoin) return t;
    }
    return -1;
  }
  NodeLog log_{0, false};
  bool fresh_ = true;
  bool overlapping_ = false;
};

TEST_F(RejoinWatchTest, UnheardWhileOthersAreHeardMakesANewParticipantAndTheWaitDoubles) {
  RejoinWatch w(0, 20.0, log_);
  w.start(0);
  const std::int64_t first = hear(w, 0, 60 * kS, kOthers);
  EXPECT_EQ(first, 20 * kS);
  EXPECT_DOUBLE_EQ(w.wait_s(), 40.0);
  w.made(first);
  EXPECT_EQ(w.rejoins(), 1U);
  fresh_ = false;
  const std::int64_t second = hear(w, first + 200 * kMs, 200 * kS, kOthers);
  EXPECT_EQ(second, first + 40 * kS) << "the unanswered rejoin did not double the wait";
}

TEST_F(RejoinWatchTest, NoNewParticipantWhenHeardOrWhenTheHostHearsNobody) {
  RejoinWatch w(0, 20.0, log_);
  w.start(0);
  EXPECT_EQ(hear(w, 0, 60 * kS, kOthers | kSelf), -1);
  RejoinWatch nobody(0, 20.0, log_);
  nobody.start(0);
  EXPECT_EQ(hear(nobody, 0, 60 * kS, 0), -1);
  RejoinWatch off(0, 0.0, log_);
  off.start(0);
  EXPECT_EQ(hear(off, 0, 60 * kS, kOthers), -1);
}

TEST_F(RejoinWatchTest, AStalledLoopOrALostHostIsNoEvidence) {
  RejoinWatch w(0, 20.0, log_);
  w.start(0);
  EXPECT_EQ(hear(w, 0, 60 * kS, kOthers, {true, false, true}), -1);
  // The wait starts again once the loop runs.
  fresh_ = false;
  EXPECT_EQ(hear(w, 60 * kS, 100 * kS, kOthers), 59'800 * kMs + 20 * kS);  // from the last stalled pass
  RejoinWatch lost(0, 20.0, log_);
  lost.start(0);
  EXPECT_EQ(hear(lost, 0, 60 * kS, kOthers, {true, true, false}), -1);
}

TEST_F(RejoinWatchTest, TheOldParticipantRetiresOnceTheNewOneIsNamedAndHearsTheHost) {
  RejoinWatch w(0, 20.0, log_);
  w.start(0);
  const std::int64_t made = hear(w, 0, 60 * kS, kOthers);
  ASSERT_GT(made, 0);
  w.made(made);
  overlapping_ = true;
  // Named within the host's window of the new participant: the old one's doing still.
  w.heard(kOthers | kSelf, made + 1 * kS, false, false);
  EXPECT_FALSE(w.poll(made + 1 * kS, kWatched, true).retire_old);
  // Named later, but only heard on the old participant: not yet.
  w.heard(kOthers | kSelf, made + 3 * kS, false, false);
  EXPECT_FALSE(w.poll(made + 3 * kS, kWatched, true).retire_old);
  w.heard(kOthers | kSelf, made + 3 * kS + 200 * kMs, false, true);
  EXPECT_TRUE(w.poll(made + 3 * kS + 200 * kMs, kWatched, true).retire_old);
  EXPECT_DOUBLE_EQ(w.wait_s(), 20.0) << "an answered rejoin keeps the back-off";
}

TEST_F(RejoinWatchTest, AHostLostAfterItHeardOnlyOthersWasThisParticipantsDoing) {
  RejoinWatch w(0, 20.0, log_);
  w.start(0);
  w.heard(kOthers | kSelf, 1 * kS, true, true);
  for (std::int64_t t = 1 * kS; t <= 10 * kS; t += 200 * kMs) w.heard(kOthers, t, false, true);
  EXPECT_TRUE(w.host_lost(10 * kS, false));
  EXPECT_FALSE(w.host_lost(10 * kS, true)) << "a stalled loop withholds the heartbeat on purpose";
  RejoinWatch named(0, 20.0, log_);
  named.start(0);
  for (std::int64_t t = 1 * kS; t <= 10 * kS; t += 200 * kMs) named.heard(kOthers | kSelf, t, t == 1 * kS, true);
  EXPECT_FALSE(named.host_lost(10 * kS, false)) << "a host that died hearing us is only waited for";
}

TEST_F(RejoinWatchTest, AFailedRemakeIsRetriedLessOftenWhileTheReasonHolds) {
  RejoinWatch w(0, 20.0, log_);
  w.start(0);
  const std::int64_t first = hear(w, 0, 60 * kS, kOthers);
  ASSERT_GT(first, 0);
  w.failed(first, "no certificate");
  EXPECT_TRUE(w.pending());
  EXPECT_EQ(w.next_attempt_ns(), first + RejoinWatch::kRemakeRetryNs);
  w.heard(kOthers, first + 500 * kMs, false, true);
  EXPECT_FALSE(w.poll(first + 500 * kMs, kWatched, false).rejoin);
  w.heard(kOthers, first + 1 * kS, false, true);
  ASSERT_TRUE(w.poll(first + 1 * kS, kWatched, false).rejoin);
  w.failed(first + 1 * kS, "no certificate");
  EXPECT_EQ(w.next_attempt_ns(), first + 1 * kS + 2 * RejoinWatch::kRemakeRetryNs);
  // Named again: whatever asked for a new participant holds no more.
  w.heard(kOthers | kSelf, first + 2 * kS, false, true);
  EXPECT_FALSE(w.poll(first + 2 * kS, kWatched, false).rejoin);
  EXPECT_FALSE(w.pending());
}

}  // namespace
}  // namespace tensegrity::fw::comms
