// SPDX-License-Identifier: Apache-2.0
// The CANopen start-up sequence (firmware/drivers/canopen_bring_up.hpp) through its
// master, against emulated nodes on a simulated bus (bench.hpp).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "bench_steps.hpp"
#include "firmware/drivers/sdo_abort.hpp"

namespace tensegrity::fw::canopen {
namespace {

using sim::Bench;
using ::testing::HasSubstr;

TEST(CanopenBringUp, BringUpSetsCspStartsNodesAndEnablesTheDrive) {
  Bench b;
  bring_up(b);
  EXPECT_EQ(b.drive.mode(), kModeCyclicSynchronousPosition);
  EXPECT_EQ(b.drive.nmt_state(), NmtState::operational);
  EXPECT_EQ(b.load_cell.nmt_state(), NmtState::operational);
  EXPECT_EQ(b.drive.state(), Cia402State::operation_enabled);
  EXPECT_EQ(b.master.drive().state, Cia402State::operation_enabled);
  EXPECT_EQ(b.master.drive().mode_display, kModeCyclicSynchronousPosition);
  // The power-up sequence in CiA 402 order, each step confirmed before the next.
  std::vector<std::uint16_t> distinct;
  for (const std::uint16_t cw : b.drive.controlwords) {
    if (distinct.empty() || distinct.back() != cw) distinct.push_back(cw);
  }
  EXPECT_THAT(distinct, ::testing::ElementsAre(0x00, 0x06, 0x07, 0x0F));
  EXPECT_TRUE(has_event(b.take_events(), MasterEventKind::bring_up_done, 3));
  EXPECT_EQ(b.master.rx_drops().total(), 0U);
}

// The SYNC period reaches the drive: 0x1006 in microseconds and 0x60C2 as value x
// 10^index s, which the emulated drive then runs at (its power-on period is 1 ms).
TEST(CanopenBringUp, BringUpGivesTheDriveTheSyncPeriod) {
  CanopenMasterConfig config = sim::bench_config();
  config.sync_period_ns = 2'000'000;
  Bench b(config);
  EXPECT_EQ(b.drive.interpolation_period_ns(), 1'000'000);
  bring_up(b);
  EXPECT_EQ(b.drive.cycle_period_ns(), 2'000'000);
  EXPECT_EQ(b.drive.interpolation_period_ns(), 2'000'000);
}

TEST(CanopenBringUp, TheInterpolationPeriodIsSaidInItsShortestForm) {
  const auto two_ms = interpolation_period(2'000'000);
  ASSERT_TRUE(two_ms.has_value());
  EXPECT_EQ(two_ms->value, 2);
  EXPECT_EQ(two_ms->index, -3);
  const auto quarter_ms = interpolation_period(250'000);
  ASSERT_TRUE(quarter_ms.has_value());
  EXPECT_EQ(quarter_ms->value, 25);
  EXPECT_EQ(quarter_ms->index, -5);
  for (const std::int64_t ns :
       {std::int64_t{100'000}, std::int64_t{1'000'000}, std::int64_t{2'500'000}, std::int64_t{1'000'000'000}}) {
    ASSERT_TRUE(interpolation_period(ns).has_value()) << ns;
    EXPECT_EQ(period_ns(*interpolation_period(ns)), ns);
  }
  EXPECT_FALSE(interpolation_period(1'234'000).has_value()) << "more than 255 before a power of ten";
  EXPECT_FALSE(interpolation_period(0).has_value());
  EXPECT_EQ(period_ns(InterpolationPeriod{1, 1}), -1);
}

TEST(CanopenBringUp, BringUpFailsClearlyWhenTheDriveIsSilent) {
  Bench b;
  b.load_cell.boot(0, b.device_log);  // the load cell is there, the drive is not
  b.master.start_bring_up(b.clock.now_ns());
  ASSERT_TRUE(b.run_until([&] { return b.master.bring_up_step() == BringUpStep::failed; }, 2'100));
  EXPECT_THAT(b.master.bring_up_failure(), HasSubstr("no heartbeat"));
  EXPECT_TRUE(has_event(b.take_events(), MasterEventKind::bring_up_failed, 3));
}

TEST(CanopenBringUp, BringUpFailsWithTheAbortTextWhenCspIsRefused) {
  Bench b;
  b.power_on();
  b.master.start_bring_up(b.clock.now_ns());
  // Its heartbeat time (0x1017) is taken; the mode is what it refuses.
  ASSERT_TRUE(b.run_until([&] { return b.master.bring_up_step() == BringUpStep::set_mode; }, 100));
  b.drive.script.sdo_abort_all = sdo_abort::kValueRange;
  ASSERT_TRUE(b.run_until([&] { return b.master.bring_up_step() == BringUpStep::failed; }, 100));
  EXPECT_THAT(b.master.bring_up_failure(), HasSubstr("0x6060"));
  EXPECT_THAT(b.master.bring_up_failure(), HasSubstr("invalid value for parameter"));
  EXPECT_EQ(b.drive.state(), Cia402State::switch_on_disabled);
}

// A stop asked while the drives are being enabled ends the sequence (the nodes are
// up) with the drives left stopped: the stop outlasts the bring-up.
TEST(CanopenBringUp, AStopDuringEnableEndsItWithTheDrivesStopped) {
  Bench b;
  b.power_on();
  b.master.start_bring_up(b.clock.now_ns());
  ASSERT_TRUE(b.run_until([&] { return b.master.bring_up_step() == BringUpStep::enable; }, 200))
      << to_string(b.master.bring_up_step()) << " " << b.master.bring_up_failure();
  b.master.request_power(PowerRequest::disabled);
  ASSERT_TRUE(b.run_until([&] { return b.master.bring_up_step() == BringUpStep::done; }, 10));
  EXPECT_NE(b.master.drive().state, Cia402State::operation_enabled);
  EXPECT_EQ(b.master.power_request(), PowerRequest::disabled);
}

// Started again, the sequence begins afresh: the failure text of the last attempt
// goes, and a node that answers now is brought up.
TEST(CanopenBringUp, ARestartForgetsTheLastFailure) {
  Bench b;
  b.load_cell.boot(0, b.device_log);
  b.master.start_bring_up(b.clock.now_ns());
  ASSERT_TRUE(b.run_until([&] { return b.master.bring_up_step() == BringUpStep::failed; }, 2'100));
  b.power_on();
  b.master.start_bring_up(b.clock.now_ns());
  EXPECT_STREQ(b.master.bring_up_failure(), "");
  ASSERT_TRUE(b.run_until([&] { return b.master.bring_up_step() == BringUpStep::done; }, 200))
      << to_string(b.master.bring_up_step()) << " " << b.master.bring_up_failure();
}

}  // namespace
}  // namespace tensegrity::fw::canopen
