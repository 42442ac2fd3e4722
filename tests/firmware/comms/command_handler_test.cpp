// SPDX-License-Identifier: Apache-2.0
// CommandHandler's decisions without DDS: samples as the node makes them, the sync
// estimate and the loop's cycle given by the test.
#include "firmware/comms/node/command_handler.hpp"

#include <gtest/gtest.h>

#include "msgs/format_version.hpp"

namespace tensegrity::fw::comms {
namespace {

constexpr int kEndcap = 2;
constexpr std::uint32_t kLife = 0x1235;
constexpr std::int64_t kMaxAgeNs = 5'000'000'000;
constexpr std::int64_t kNow = 10'000'000'000;            // node clock
const SyncView kSynced{true, 1'000'000'000, 1'000'000};  // host = node + 1 s

CommandSample command(WireCommandKind kind, std::uint32_t seq) {
  CommandSample c;
  c.writer[0] = 7;
  c.format_version = msgs::kFormatVersion;
  c.seq = seq;
  c.kind = static_cast<std::uint8_t>(kind);
  c.endcap_mask = 1U << kEndcap;
  c.issued_host_time_ns = kNow + kSynced.offset_ns;
  c.start_host_time_ns = kNow + kSynced.offset_ns + 500'000'000;
  c.asked_host_time_ns = c.issued_host_time_ns;
  return c;
}

LoopPoint ready_loop() {
  LoopPoint p;
  p.clock = LoopClockPoint{4'000'000'000, kNow};  // loop time 4 s at node time kNow
  p.ready = LoopReadiness{true, core::FaultCause::none, true};
  return p;
}

class CommandHandlerTest : public ::testing::Test {
 protected:
  NodeLog log_{kEndcap, false};
  CommandHandler handler_{kEndcap, msgs::kFormatVersion, kMaxAgeNs, 0, kLife, log_};
};

TEST_F(CommandHandlerTest, AnEmergencyStopIsCountedAtOnceAndNeverMailed) {
  const auto reason = handler_.handle(command(WireCommandKind::emergency_stop, 1), SyncView{}, kNow);
  ASSERT_TRUE(reason.has_value());
  EXPECT_EQ(*reason, CommandReason::accepted);
  EXPECT_EQ(handler_.estops(), 1U);
  app::HostCommand out;
  EXPECT_FALSE(handler_.take(out)) << "an emergency stop went through the mailbox";
}

TEST_F(CommandHandlerTest, ARepeatedEstopIsAckedAgainButCountedOnce) {
  const CommandSample c = command(WireCommandKind::emergency_stop, 1);
  handler_.handle(c, kSynced, kNow);
  const auto again = handler_.handle(c, kSynced, kNow);
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ(*again, CommandReason::accepted);
  EXPECT_EQ(handler_.estops(), 1U);
}

TEST_F(CommandHandlerTest, OtherEndcapsCommandsGetNoAnswer) {
  CommandSample c = command(WireCommandKind::stop, 1);
  c.endcap_mask = static_cast<std::uint16_t>(~(1U << kEndcap) & 0x0FFF);
  EXPECT_FALSE(handler_.handle(c, kSynced, kNow).has_value());
}

TEST_F(CommandHandlerTest, AStopCarriesTheEstopsBeforeIt) {
  handler_.handle(command(WireCommandKind::emergency_stop, 1), kSynced, kNow);
  ASSERT_EQ(handler_.handle(command(WireCommandKind::stop, 2), kSynced, kNow), CommandReason::accepted);
  app::HostCommand out;
  ASSERT_TRUE(handler_.take(out));
  EXPECT_EQ(out.kind, app::CommandKind::stop);
  EXPECT_EQ(out.estops_before, 1U);
}

TEST_F(CommandHandlerTest, AStartNeedsASyncedClockAndARunningReadyLoop) {
  EXPECT_EQ(handler_.handle(command(WireCommandKind::start, 1), SyncView{}, kNow), CommandReason::clock_not_synced);
  EXPECT_EQ(handler_.handle(command(WireCommandKind::start, 2), kSynced, kNow), CommandReason::loop_not_running);
  LoopPoint not_ready = ready_loop();
  not_ready.ready.has_table = false;
  handler_.note_loop(not_ready);
  const auto no_table = handler_.handle(command(WireCommandKind::start, 3), kSynced, kNow);
  EXPECT_NE(no_table, CommandReason::accepted);
  app::HostCommand out;
  EXPECT_FALSE(handler_.take(out)) << "a refused start reached the loop";
}

TEST_F(CommandHandlerTest, AStartIsMappedOntoTheLoopsClock) {
  handler_.note_loop(ready_loop());
  ASSERT_EQ(handler_.handle(command(WireCommandKind::start, 1), kSynced, kNow), CommandReason::accepted);
  app::HostCommand out;
  ASSERT_TRUE(handler_.take(out));
  EXPECT_EQ(out.kind, app::CommandKind::start);
  // Host start = node kNow + 0.5 s; the loop was at 4 s at node kNow.
  EXPECT_EQ(out.start_time_ns, 4'500'000'000);
}

TEST_F(CommandHandlerTest, AStaleStartIsRefused) {
  handler_.note_loop(ready_loop());
  const std::int64_t later = kNow + kMaxAgeNs + 1'000'000'000;
  EXPECT_NE(handler_.handle(command(WireCommandKind::start, 1), kSynced, later), CommandReason::accepted);
}

TEST_F(CommandHandlerTest, AClearFaultMustHaveSeenEveryEstop) {
  handler_.handle(command(WireCommandKind::emergency_stop, 1), kSynced, kNow);
  CommandSample clear = command(WireCommandKind::clear_fault, 2);
  clear.estops_seen = EstopCount{kLife, 0};
  EXPECT_EQ(handler_.handle(clear, kSynced, kNow), CommandReason::estop_unseen);
  clear.seq = 3;
  clear.estops_seen = EstopCount{kLife, 1};
  EXPECT_EQ(handler_.handle(clear, kSynced, kNow), CommandReason::accepted);
}

TEST_F(CommandHandlerTest, TheMailboxFullIsSaid) {
  for (std::uint32_t s = 1; s <= CommandHandler::kMailboxCapacity; ++s) {
    handler_.handle(command(WireCommandKind::stop, s), kSynced, kNow);
  }
  const auto reason = handler_.handle(command(WireCommandKind::stop, 100), kSynced, kNow);
  EXPECT_EQ(reason, CommandReason::mailbox_full);
}

}  // namespace
}  // namespace tensegrity::fw::comms
