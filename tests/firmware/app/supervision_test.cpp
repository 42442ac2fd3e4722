// SPDX-License-Identifier: Apache-2.0
// The end cap's supervision of its nodes, each detector on its own: an unexpected
// boot-up, a drive leaving operation enabled, a stale drive position. Each is a
// latched fault, reported in telemetry, with the motors held from the cycle that
// detected it (quick stop, or for a stale position the last measured one).
#include <gtest/gtest.h>

#include "app_bench.hpp"
#include "tests/support/alloc_counter.hpp"

namespace tensegrity::fw::app::test {
namespace {

using canopen::Cia402State;
using canopen::PowerRequest;
using core::FaultCause;

// The safe state the loop must be in once `cause` is latched.
// A stale position holds the last measured one with the drives enabled, as the
// other sensor faults do; the rest quick-stop every drive.
void expect_safe_state(const AppBench& b, FaultCause cause) {
  EXPECT_EQ(b.loop->controller().fault(), cause);
  EXPECT_EQ(b.loop->controller().mode(), core::Mode::faulted);
  const PowerRequest expected =
      cause == FaultCause::stale_position ? PowerRequest::operation_enabled : PowerRequest::quick_stop;
  EXPECT_EQ(b.loop->master().power_request(), expected);
  EXPECT_EQ(b.host.last.fault, cause) << "reported in telemetry";
  EXPECT_EQ(b.host.last.mode, core::Mode::faulted);
}

TEST(Supervision, UnexpectedBootUpOfADriveTripsInTheCycleThatSeesIt) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  for (int i = 0; i < 50; ++i) b.cycle();
  sim::FrameOut out;
  b.drive1.reboot(b.clock.now_ns(), out);  // boot-up, pre-operational, unpowered
  for (const CanFrame& f : out) b.bus.inject_to_receiver(f);
  b.cycle();
  expect_safe_state(b, FaultCause::node_rebooted);
  b.cycle();
  EXPECT_EQ(b.drive0.state(), Cia402State::quick_stop_active) << "the healthy drive stops with it";
  EXPECT_EQ(b.drive1.state(), Cia402State::switch_on_disabled);
  for (int i = 0; i < 100; ++i) b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::node_rebooted) << "latched";
}

TEST(Supervision, BootUpsDuringBringUpAreExpected) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::none) << "bring-up resets every node: their boot-ups are fine";
  EXPECT_GE(b.loop->master().heartbeat(canopen::NodeRole::drive).boot_ups, 2U);
}

TEST(Supervision, UnexpectedBootUpOfTheLoadCellTrips) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  for (int i = 0; i < 20; ++i) b.cycle();
  sim::FrameOut out;
  b.load_cell.reboot(b.clock.now_ns(), out);
  for (const CanFrame& f : out) b.bus.inject_to_receiver(f);
  b.cycle();
  expect_safe_state(b, FaultCause::node_rebooted);
}

TEST(Supervision, ARebootedDriveIsBroughtUpAgainAfterAClear) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  sim::FrameOut out;
  b.drive0.reboot(b.clock.now_ns(), out);
  for (const CanFrame& f : out) b.bus.inject_to_receiver(f);
  b.cycle();
  ASSERT_EQ(b.loop->controller().fault(), FaultCause::node_rebooted);
  b.host.commands.push_back({CommandKind::clear_fault, 0});
  ASSERT_TRUE(b.run_until([&] { return b.loop->drives_enabled(); }, 500));
  for (int i = 0; i < 100; ++i) b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::none);
  EXPECT_EQ(b.drive0.consumer_time_ms(), 50) << "reconfigured: a rebooted drive forgot its consumer";
}

TEST(Supervision, DriveLeavingOperationEnabledUnaskedTrips) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  for (int i = 0; i < 20; ++i) b.cycle();
  b.drive0.on_connection_lost();  // behind the end cap's back: switch on disabled
  b.cycle();                      // its TPDO1 says so at this SYNC ...
  b.cycle();                      // ... read in this cycle
  expect_safe_state(b, FaultCause::drive_disabled);
}

TEST(Supervision, StalePositionTripsAfterItsTimeout) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  for (int i = 0; i < 20; ++i) b.cycle();
  b.drive1.tpdo_on_sync = false;  // heartbeat goes on, positions stop
  b.cycle();                      // reads the answer to the last SYNC it did answer
  const std::int64_t last_ns = b.loop->master().drive(1).position_updated_ns;
  ASSERT_TRUE(b.run_until([&] { return b.loop->controller().fault() != FaultCause::none; }, 200));
  expect_safe_state(b, FaultCause::stale_position);
  const std::int64_t age_ns = b.loop->status().time_ns - last_ns;
  EXPECT_GT(age_ns, b.settings.safety.drive_position_timeout_ns);
  EXPECT_LE(age_ns, b.settings.safety.drive_position_timeout_ns + b.settings.period_ns) << "checked every cycle";
  EXPECT_TRUE(b.loop->master().drive_heartbeat(1).alive) << "found before any heartbeat timeout";
}

TEST(Supervision, AStalePositionDoesNotHideADriveLeavingOperationEnabled) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  for (int i = 0; i < 20; ++i) b.cycle();
  b.drive0.tpdo_on_sync = false;  // drive 0's positions stop: a milder fault, drives kept enabled
  ASSERT_TRUE(b.run_until([&] { return b.loop->controller().fault() != FaultCause::none; }, 200));
  ASSERT_EQ(b.loop->controller().fault(), FaultCause::stale_position);
  b.drive1.on_connection_lost();  // then drive 1 drops out behind the end cap's back
  b.cycle();                      // its TPDO1 says so at this SYNC ...
  b.cycle();                      // ... read in this cycle, as with no other fault latched
  EXPECT_EQ(b.loop->master().power_request(), PowerRequest::quick_stop) << "the drop is seen and quick-stops";
  for (int i = 0; i < 50; ++i) b.cycle();
  EXPECT_NE(b.drive1.state(), Cia402State::operation_enabled) << "not stepped back up unseen";
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::stale_position) << "the first cause stays the one reported";
}

TEST(Supervision, AStalePositionIsSeenWhileAClearedDriveIsStillComingUp) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  for (int i = 0; i < 20; ++i) b.cycle();
  b.drive0.on_connection_lost();
  b.cycle();
  b.cycle();
  ASSERT_EQ(b.loop->controller().fault(), FaultCause::drive_disabled);
  // Drive 0 cannot reach operation enabled after the clear (held at its enable
  // gate); its power state is not judged during the reset grace. Drive 1's
  // positions stop meanwhile: that must trip within its own timeout, not when
  // the grace ends.
  b.drive0.hold_enable = true;
  b.host.commands.push_back({CommandKind::clear_fault, 0});
  b.cycle();
  ASSERT_EQ(b.loop->controller().fault(), FaultCause::none);
  b.drive1.tpdo_on_sync = false;
  b.cycle();
  const std::int64_t last_ns = b.loop->master().drive(1).position_updated_ns;
  ASSERT_TRUE(b.run_until([&] { return b.loop->controller().fault() != FaultCause::none; }, 400));
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::stale_position);
  const std::int64_t age_ns = b.loop->status().time_ns - last_ns;
  EXPECT_LE(age_ns, b.settings.safety.drive_position_timeout_ns + b.settings.period_ns);
  EXPECT_LT(age_ns, b.settings.fault_reset_grace_ns / 2) << "found inside the grace";
  EXPECT_NE(b.drive0.state(), Cia402State::operation_enabled);
}

TEST(Supervision, FreshPositionsAndSamplesNeverTrip) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  for (int i = 0; i < 2000; ++i) b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::none);
  EXPECT_TRUE(b.running());
}

TEST(Supervision, EndCapHeartbeatComesFromTheLoopAndStopsWithIt) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  for (int i = 0; i < 30; ++i) b.cycle();
  const std::uint64_t sent = b.loop->master().heartbeats_sent();
  EXPECT_GT(sent, 0U);
  ASSERT_TRUE(b.drive0.consumer_armed());
  // The loop hangs: the devices' time goes on, no cycle runs.
  for (int i = 0; i < 60; ++i) {
    b.clock.advance_ns(b.settings.period_ns);
    b.bus.tick();
  }
  EXPECT_EQ(b.loop->master().heartbeats_sent(), sent);
  EXPECT_EQ(b.drive0.state(), Cia402State::quick_stop_active) << "stopped by the drive itself (0x6007)";
  EXPECT_EQ(b.drive1.state(), Cia402State::quick_stop_active);
}

// A loop that hung (SIGSTOP, a blocked driver) and resumes must not undo what the
// drives did on their own: its cached states still say "operation enabled", and an
// "enable operation" to a drive in quick stop is CiA 402's transition 16.
TEST(Supervision, ALoopThatResumesAfterAStallLatchesAFaultAndLeavesItsDrivesStopped) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  for (int i = 0; i < 30; ++i) b.cycle();
  for (int i = 0; i < 60; ++i) {
    b.clock.advance_ns(b.settings.period_ns);
    b.bus.tick();
  }
  ASSERT_EQ(b.drive0.state(), Cia402State::quick_stop_active);
  b.cycle();
  expect_safe_state(b, FaultCause::loop_stalled);
  for (int i = 0; i < 200; ++i) b.cycle();
  EXPECT_EQ(b.drive0.state(), Cia402State::quick_stop_active) << "not re-enabled without an operator";
  EXPECT_EQ(b.drive1.state(), Cia402State::quick_stop_active);
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::loop_stalled) << "latched";
  // An operator's clear brings them back.
  b.host.commands.push_back({CommandKind::clear_fault, 0});
  ASSERT_TRUE(b.run_until([&] { return b.loop->drives_enabled(); }, 500));
  for (int i = 0; i < 100; ++i) b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::none);
}

TEST(Supervision, AShortLateWakeUpIsNotAStall) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  for (int i = 0; i < 30; ++i) b.cycle();
  b.clock.advance_ns(10 * b.settings.period_ns);  // 10 ms late: an overrun, the drives saw no gap
  for (int i = 0; i < 100; ++i) b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::none);
  EXPECT_TRUE(b.running());
}

TEST(Supervision, DetectorsAllocateNothing) {
  AppBench b;
  b.drive0.controlwords.reserve(100'000);
  b.drive1.controlwords.reserve(100'000);
  ASSERT_TRUE(b.start_running());
  for (int i = 0; i < 50; ++i) b.cycle();
  b.drive1.tpdo_on_sync = false;
  std::size_t allocations = 0;
  for (int i = 0; i < 100; ++i) {
    b.bus.tick();
    const tensegrity::test::AllocationScope scope;
    b.loop->run_realtime_cycle();
    allocations += scope.count();
  }
  EXPECT_EQ(allocations, 0U);
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::stale_position);
}

}  // namespace
}  // namespace tensegrity::fw::app::test
