// SPDX-License-Identifier: Apache-2.0
// What the node's reports say, built without a participant.
#include "firmware/comms/node/node_messages.hpp"

#include <gtest/gtest.h>

#include "msgs/format_version.hpp"

namespace tensegrity::fw::comms {
namespace {

NodeFacts facts(bool synced) {
  NodeFacts f;
  f.endcap_id = 5;
  f.active = {"gait", 3, 0xABCD};
  f.sync = SyncView{synced, 2'000, 300};
  f.host_lost = true;
  f.host_loss = HostLossAction::stop;
  f.life_id = 0x51;
  f.estops = 2;
  return f;
}

TEST(NodeMessages, TelemetryHasHostTimeOnlyOnceSynced) {
  app::Telemetry t{};
  t.time_ns = 7'000;
  t.tension_n[1] = 12.5;
  const auto synced = telemetry_message(facts(true), 9, t, 1'000);
  EXPECT_EQ(synced.host_time_ns(), 3'000);
  EXPECT_EQ(synced.loop_time_ns(), 7'000);
  EXPECT_EQ(synced.seq(), 9U);
  EXPECT_EQ(synced.endcap_id(), 5);
  EXPECT_DOUBLE_EQ(synced.tension_n()[1], 12.5);
  EXPECT_EQ(synced.active_policy_id(), "gait");
  EXPECT_EQ(telemetry_message(facts(false), 9, t, 1'000).host_time_ns(), 0);
}

TEST(NodeMessages, TheHeartbeatSaysHostLossEstopsAndClock) {
  const auto hb = heartbeat_message(facts(true), 4, 123, app::Telemetry{});
  EXPECT_EQ(hb.format_version(), msgs::kFormatVersion);
  EXPECT_EQ(hb.source(), 5);
  EXPECT_TRUE(hb.host_lost());
  EXPECT_EQ(hb.host_loss_action(), static_cast<std::uint8_t>(HostLossAction::stop));
  EXPECT_EQ(hb.life_id(), 0x51U);
  EXPECT_EQ(hb.estops_received(), 2U);
  EXPECT_TRUE(hb.clock_synced());
  EXPECT_EQ(hb.clock_offset_ns(), 2'000);
  EXPECT_EQ(hb.clock_round_trip_ns(), 300);
}

TEST(NodeMessages, AcksCarryTheReasonAndTheActivePolicy) {
  core::EndcapTable table;
  const PolicyTableMsg msg = make_policy_message(table, 5, PolicyIdentity{"x", 1, "", false}, 77);
  const auto ack = policy_ack_message(facts(true), msg, PolicyReason::stale_version, std::string(300, 'a'));
  EXPECT_EQ(ack.upload_sequence(), 77U);
  EXPECT_FALSE(ack.accepted());
  EXPECT_EQ(ack.reason_text().size(), 128U);
  EXPECT_EQ(ack.active_checksum(), 0xABCDU);
  const auto cmd = command_ack_message(facts(true), 12, CommandReason::accepted);
  EXPECT_TRUE(cmd.accepted());
  EXPECT_EQ(cmd.seq(), 12U);
  EXPECT_EQ(cmd.estops_received(), 2U);
}

}  // namespace
}  // namespace tensegrity::fw::comms
