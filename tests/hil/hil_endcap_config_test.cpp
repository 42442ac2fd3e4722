// SPDX-License-Identifier: Apache-2.0
// The config the launcher writes for an end cap: the robot's limits pass through, and
// real time widens every silence timeout to the host's stall bound while lockstep keeps
// the firmware's defaults.
#include "hil/endcap_config.hpp"

#include <gtest/gtest.h>

#include "hil/endcap_devices.hpp"

namespace tensegrity::hil {
namespace {

LauncherConfig launcher(StepperMode mode) {
  LauncherConfig lc;
  lc.mode = mode;
  lc.hub_port = 40000;
  lc.limits.cutoff_tension_n = 350.0;
  lc.limits.overload = core::Overload::pay_out;
  return lc;
}

TEST(HilEndcapConfig, CarriesTheRobotsLimitsAndDrives) {
  const auto c = endcap_config(launcher(StepperMode::lockstep), 2, 40001, "/tmp/store");
  EXPECT_EQ(c.limits.cutoff_tension_n, 350.0);
  EXPECT_EQ(c.limits.overload, core::Overload::pay_out);
  EXPECT_EQ(c.motor_count, 2U);
  EXPECT_EQ(c.drive_node_ids[1], kDriveNodeIds[1]);
  EXPECT_EQ(c.bus, "udp:127.0.0.1:40000,bind=127.0.0.1:40001,batch");
  // What the launcher writes is what the end cap reads back.
  const auto back = fw::app::parse_config(fw::app::config_to_json_text(c), 0);
  EXPECT_EQ(back.limits.overload, core::Overload::pay_out);
  EXPECT_EQ(back.limits.cutoff_tension_n, 350.0);
}

TEST(HilEndcapConfig, RealTimeWidensEverySilenceTimeout) {
  const auto c = endcap_config(launcher(StepperMode::realtime), 2, 40001, "/tmp/store");
  EXPECT_EQ(c.mode, fw::app::LoopMode::realtime);
  EXPECT_EQ(c.drive_consumer_heartbeat_s, kRealtimeConsumerHeartbeatS);
  EXPECT_EQ(c.drive_heartbeat_timeout_s, kRealtimeSilenceTimeoutS);
  EXPECT_EQ(c.load_cell_heartbeat_timeout_s, kRealtimeSilenceTimeoutS);
  EXPECT_EQ(c.load_cell_sample_timeout_s, kRealtimeSilenceTimeoutS);
  EXPECT_EQ(c.drive_position_timeout_s, kRealtimeSilenceTimeoutS);
}

TEST(HilEndcapConfig, LockstepKeepsTheFirmwareDefaults) {
  const auto c = endcap_config(launcher(StepperMode::lockstep), 2, 40001, "/tmp/store");
  const fw::app::EndcapAppConfig defaults;
  EXPECT_EQ(c.mode, fw::app::LoopMode::lockstep);
  EXPECT_EQ(c.drive_consumer_heartbeat_s, defaults.drive_consumer_heartbeat_s);
  EXPECT_EQ(c.drive_position_timeout_s, defaults.drive_position_timeout_s);
  EXPECT_LT(c.drive_position_timeout_s, kRealtimeSilenceTimeoutS);
  EXPECT_LT(c.load_cell_sample_timeout_s, kRealtimeSilenceTimeoutS);
}

}  // namespace
}  // namespace tensegrity::hil
