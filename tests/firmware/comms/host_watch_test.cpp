// SPDX-License-Identifier: Apache-2.0
// Host loss with fake time: the boot grace, the timeout, the stop asked while lost.
#include "firmware/comms/node/host_watch.hpp"

#include <gtest/gtest.h>

namespace tensegrity::fw::comms {
namespace {

constexpr std::int64_t kS = 1'000'000'000;
constexpr std::uint16_t kVersion = 6;

class HostWatchTest : public ::testing::Test {
 protected:
  HostWatch make(HostLossAction action) { return HostWatch(1.0, 30.0, action, kVersion, log_); }
  NodeLog log_{0, false};
};

TEST_F(HostWatchTest, NoHostWithinTheBootGraceIsALostHost) {
  HostWatch w = make(HostLossAction::stop);
  w.start(100 * kS);
  EXPECT_FALSE(w.poll(130 * kS));
  EXPECT_FALSE(w.lost());
  EXPECT_TRUE(w.poll(130 * kS + 1));
  EXPECT_TRUE(w.lost());
  EXPECT_EQ(w.stops(), 1U);
  EXPECT_EQ(w.losses(), 1U);
}

TEST_F(HostWatchTest, SilenceAfterAHeartbeatIsLostAfterTheTimeoutAndAStopIsAskedEveryCheck) {
  HostWatch w = make(HostLossAction::stop);
  w.start(0);
  w.heard(1 * kS);
  EXPECT_FALSE(w.poll(2 * kS));
  EXPECT_EQ(w.stops(), 0U);
  EXPECT_TRUE(w.poll(2 * kS + 1));
  EXPECT_EQ(w.stops(), 1U);
  // Still lost: asked again, so a start taken meanwhile does not play unwatched.
  EXPECT_FALSE(w.poll(3 * kS));
  EXPECT_FALSE(w.poll(4 * kS));
  EXPECT_EQ(w.stops(), 3U);
  EXPECT_EQ(w.losses(), 1U);
  // Back: no more stops, counted as a return.
  EXPECT_TRUE(w.fresh());
  w.heard(5 * kS);
  EXPECT_FALSE(w.poll(5 * kS));
  EXPECT_FALSE(w.lost());
  EXPECT_FALSE(w.fresh());
  EXPECT_EQ(w.returns(), 1U);
  w.poll(5 * kS + 1);
  EXPECT_EQ(w.stops(), 3U);
}

TEST_F(HostWatchTest, ContinueReportsTheLossButAsksNoStop) {
  HostWatch w = make(HostLossAction::continue_gait);
  w.start(0);
  w.heard(0);
  EXPECT_TRUE(w.poll(2 * kS));
  w.poll(3 * kS);
  EXPECT_TRUE(w.lost());
  EXPECT_EQ(w.stops(), 0U);
}

TEST_F(HostWatchTest, AnotherFormatIsRefusedAndDoesNotCount) {
  HostWatch w = make(HostLossAction::stop);
  EXPECT_FALSE(w.accepts(kVersion + 1));
  EXPECT_TRUE(w.accepts(kVersion));
  EXPECT_FALSE(w.seen());
}

}  // namespace
}  // namespace tensegrity::fw::comms
