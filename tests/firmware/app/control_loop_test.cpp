// SPDX-License-Identifier: Apache-2.0
// The control loop against scripted devices: it plays a table through both drives,
// goes to its safe state within one cycle of a fault being known, keeps it latched
// until cleared, swaps tables at period boundaries and allocates nothing per cycle.
#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "app_bench.hpp"
#include "firmware/drivers/cob_id.hpp"
#include "firmware/drivers/pdo_codec.hpp"
#include "tests/support/alloc_counter.hpp"

namespace tensegrity::fw::app::test {
namespace {

using canopen::Cia402State;
using core::FaultCause;

TEST(ControlLoop, BringsUpBothDrivesAndPlaysTheTable) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  EXPECT_TRUE(b.has_event(AppEventKind::bring_up_done));
  EXPECT_TRUE(b.has_event(AppEventKind::started));
  for (int i = 0; i < 600; ++i) b.cycle();  // 0.6 s: both halves of the 0.2 s period, several times
  EXPECT_EQ(b.drive0.state(), Cia402State::operation_enabled);
  EXPECT_EQ(b.drive1.state(), Cia402State::operation_enabled);
  // Rate limited at 0.2 m/s, a 0.1 m step takes 0.5 s: the motors move, in
  // opposite directions, and both stay within the table's range.
  const double m0 = b.target_m(b.drive0);
  const double m1 = b.target_m(b.drive1);
  EXPECT_GE(m0, 0.90 - 1e-6);
  EXPECT_LE(m0, 1.00 + 1e-6);
  EXPECT_NE(m0, m1);
  EXPECT_NEAR(b.loop->commanded_m()[0], m0, 1e-5);
  EXPECT_NEAR(b.loop->commanded_m()[1], m1, 1e-5);
  EXPECT_EQ(b.loop->status().overruns, 0U);
  EXPECT_EQ(b.host.last.motor_count, 2U);
  EXPECT_TRUE(b.host.last.drives_enabled);
}

TEST(ControlLoop, DriveEmcyTripsAndQuickStopsInOneCycle) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  for (int i = 0; i < 50; ++i) b.cycle();
  b.send_emcy(b.drive1, 0x2310);
  b.cycle();  // the EMCY is read in this cycle: safe state now
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::drive_fault);
  EXPECT_EQ(b.loop->master().power_request(), canopen::PowerRequest::quick_stop);
  const double held0 = b.loop->commanded_m()[0];
  EXPECT_NEAR(held0, b.loop->master().drive(0).rest_length_m, 1e-6) << "holds where the motor is";
  // Drive 0 goes to quick stop and stays there; drive 1 stays in fault.
  for (int i = 0; i < 100; ++i) b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::drive_fault) << "latched";
  EXPECT_DOUBLE_EQ(b.loop->commanded_m()[0], held0);
  EXPECT_EQ(b.drive0.state(), Cia402State::quick_stop_active);
  EXPECT_EQ(b.drive1.state(), Cia402State::fault);

  b.host.commands.push_back({CommandKind::clear_fault, 0});
  ASSERT_TRUE(b.run_until([&] { return b.loop->drives_enabled(); }, 100));
  for (int i = 0; i < 300; ++i) b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::none);
  EXPECT_EQ(b.loop->controller().mode(), core::Mode::idle) << "must be started again";
  b.host.commands.push_back({CommandKind::start, 0});
  b.cycle();
  EXPECT_TRUE(b.running());
}

TEST(ControlLoop, MissedDriveHeartbeatTripsDriveLostInTheSameCycle) {
  // The drive's positions stop with it and would trip stale_position first (20 ms,
  // supervision_test.cpp): here only the heartbeat path is under test.
  LoopSettings s = bench_settings();
  s.safety.drive_position_timeout_ns = 10'000'000'000;
  AppBench b(s);
  ASSERT_TRUE(b.start_running());
  b.bus.set_connected(b.drive0, false);
  int cycles = 0;
  while (b.loop->master().drive_heartbeat(0).alive && cycles < 500) {
    EXPECT_EQ(b.loop->controller().fault(), FaultCause::none);
    b.cycle();
    ++cycles;
  }
  ASSERT_FALSE(b.loop->master().drive_heartbeat(0).alive);
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::drive_lost) << "the cycle that saw the loss";
  b.bus.set_connected(b.drive0, true);
  for (int i = 0; i < 100; ++i) b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::drive_lost) << "latched after the heartbeat returns";
}

TEST(ControlLoop, StuckLoadCellTripsSensorTimeoutAfterTheSampleTimeout) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  b.load_cell.advance_sequence = false;  // answers every SYNC with the same sample
  const std::int64_t stuck_since_ns = b.clock.now_ns();
  ASSERT_TRUE(b.run_until([&] { return b.loop->controller().fault() != FaultCause::none; }, 200));
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::sensor_timeout);
  const std::int64_t after_ns = b.clock.now_ns() - stuck_since_ns;
  EXPECT_GT(after_ns, b.settings.safety.load_cell_sample_timeout_ns);
  EXPECT_LE(after_ns, b.settings.safety.load_cell_sample_timeout_ns + 3 * b.settings.period_ns);
  b.load_cell.advance_sequence = true;
  for (int i = 0; i < 50; ++i) b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::sensor_timeout) << "latched";
  b.host.commands.push_back({CommandKind::clear_fault, 0});
  b.cycle();
  b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::none) << "sensor recovered: clear sticks";
}

TEST(ControlLoop, OverTensionTripsAndHoldsInTheCycleThatReadsIt) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  for (int i = 0; i < 50; ++i) b.cycle();
  b.load_cell.sample.tension_mn[1] = 600'000;  // 600 N > 500 N hard limit
  b.cycle();                                   // SYNC of this cycle makes the load cell send it
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::none);
  b.cycle();  // reads it
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::over_tension);
  // The measured position this cycle read is where both motors stay.
  const double measured0 = b.loop->master().drive(0).rest_length_m;
  EXPECT_NEAR(b.loop->commanded_m()[0], measured0, 1e-6);
  EXPECT_NEAR(b.target_m(b.drive0), measured0, 1e-6) << "the target sent this cycle is the hold position";
  b.load_cell.sample.tension_mn[1] = 100'000;
  for (int i = 0; i < 50; ++i) b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::over_tension) << "latched until cleared";
  EXPECT_NEAR(b.target_m(b.drive0), measured0, 1e-6) << "still holding";
  b.host.commands.push_back({CommandKind::clear_fault, 0});
  b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::none);
}

TEST(ControlLoop, EmergencyStopCommandLatches) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  b.host.commands.push_back({CommandKind::emergency_stop, 0});
  b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::emergency_stop);
  EXPECT_EQ(b.loop->master().power_request(), canopen::PowerRequest::quick_stop);
}

// A host lost while the gait plays: latched as host_lost (the drives hold the measured
// rest lengths, powered) in the next cycle, and it takes a clear-fault to go on.
TEST(ControlLoop, AHostLostWhilePlayingLatchesUntilCleared) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  b.host.host_losses = 1;
  b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::host_lost);
  EXPECT_FALSE(b.running());
  EXPECT_TRUE(b.has_event(AppEventKind::fault_latched));
  EXPECT_NE(b.loop->master().power_request(), canopen::PowerRequest::quick_stop) << "held, not quick-stopped";
  b.host.commands.push_back({CommandKind::start, 0});
  b.cycle();
  EXPECT_FALSE(b.running()) << "a start without a clear-fault";
  b.host.commands.push_back({CommandKind::clear_fault, 0});
  b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::none);
}

// Idle, there is nothing to stop: a host loss latches nothing (a start can only come
// from a host that is back).
TEST(ControlLoop, AHostLostWhileIdleLatchesNothing) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  b.host.commands.push_back({CommandKind::stop, 0});
  b.cycle();
  ASSERT_FALSE(b.running());
  b.host.host_losses = 1;
  b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::none);
}

TEST(ControlLoop, EmergencyStopCounterLatchesInTheNextCycleWhateverTheMailboxHolds) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  for (int i = 0; i < 64; ++i) b.host.commands.push_back({CommandKind::stop, 0});  // a flood of stops
  b.host.estops = 1;
  b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::emergency_stop);
  EXPECT_EQ(b.loop->master().power_request(), canopen::PowerRequest::quick_stop);
}

TEST(ControlLoop, AnEstopSentBeforeAClearFaultIsAppliedBeforeIt) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  // The host sent estop, then clear-fault; both reach the loop in one cycle.
  b.host.estops = 1;
  HostCommand clear{CommandKind::clear_fault, 0};
  clear.estops_before = 1;
  b.host.commands.push_back(clear);
  b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::none) << "cleared after the estop, not before";
  EXPECT_TRUE(b.has_event(AppEventKind::fault_cleared));
  // A clear sent before the estop leaves it latched.
  HostCommand early_clear{CommandKind::clear_fault, 0};
  early_clear.estops_before = 1;
  b.host.commands.push_back(early_clear);
  b.host.estops = 2;
  b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::emergency_stop);
}

TEST(ControlLoop, AnEstopOnTopOfAMilderFaultAlsoOutlastsTheBringUp) {
  AppBench b;
  ASSERT_EQ(b.loop->load_table(bench_table()), core::TableError::none);
  b.cycle();
  CanFrame emcy;  // the load cell reports an error while the nodes come up: a fault that keeps drives enabled
  emcy.id = canopen::cob_id(canopen::Function::sync_or_emcy, 4);
  emcy.dlc = 8;
  emcy.data[1] = 0x50;  // 0x5000, device hardware
  b.bus.inject_to_receiver(emcy);
  b.cycle();
  ASSERT_EQ(b.loop->controller().fault(), FaultCause::sensor_timeout);
  b.host.estops = 1;  // then the operator's estop: the first cause stays the one reported
  b.cycle();
  EXPECT_EQ(b.loop->master().power_request(), canopen::PowerRequest::quick_stop) << "in the cycle that reads it";
  ASSERT_TRUE(b.run_until([&] { return b.has_event(AppEventKind::bring_up_done); }, 500));
  for (int i = 0; i < 200; ++i) b.cycle();
  EXPECT_NE(b.drive0.state(), Cia402State::operation_enabled) << "the bring-up did not enable them";
  EXPECT_NE(b.drive1.state(), Cia402State::operation_enabled);
  EXPECT_FALSE(b.host.last.drives_enabled);
}

TEST(ControlLoop, AClearFaultQueuedJustBeforeAnEstopNeverUndoesIt) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  // The node's thread queues a clear-fault sent before any estop, then counts an
  // estop, just as the loop reads the estop counter: the estop is the later order.
  bool raced = false;
  b.host.before_estops_read = [&] {
    if (std::exchange(raced, true)) return;
    b.host.commands.push_back({CommandKind::clear_fault, 0});  // estops_before 0
    b.host.estops = 1;
  };
  b.cycle();
  ASSERT_TRUE(raced);
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::emergency_stop) << "latched in the cycle that read it";
  EXPECT_EQ(b.loop->master().power_request(), canopen::PowerRequest::quick_stop);
  for (int i = 0; i < 3; ++i) b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::emergency_stop) << "the estop came last";
  EXPECT_FALSE(b.has_event(AppEventKind::fault_cleared));
}

TEST(ControlLoop, AnEstopLatchedDuringBringUpKeepsTheDrivesStoppedUntilCleared) {
  AppBench b;
  ASSERT_EQ(b.loop->load_table(bench_table()), core::TableError::none);
  b.host.estops = 1;  // an end cap that just restarted hears the operator's estop
  b.cycle();
  ASSERT_EQ(b.loop->controller().fault(), FaultCause::emergency_stop);
  ASSERT_TRUE(b.run_until([&] { return b.has_event(AppEventKind::bring_up_done); }, 500)) << "the nodes come up";
  for (int i = 0; i < 200; ++i) b.cycle();
  EXPECT_NE(b.drive0.state(), Cia402State::operation_enabled) << "the bring-up did not enable them";
  EXPECT_NE(b.drive1.state(), Cia402State::operation_enabled);
  EXPECT_FALSE(b.host.last.drives_enabled);
  EXPECT_FALSE(b.running());
  EXPECT_FALSE(b.has_event(AppEventKind::bring_up_failed));
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::emergency_stop);
  b.host.commands.push_back({CommandKind::clear_fault, 0});
  ASSERT_TRUE(b.run_until([&] { return b.loop->drives_enabled(); }, 100)) << "cleared, they come up";
  for (int i = 0; i < 300; ++i) b.cycle();  // past the reset grace
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::none);
  EXPECT_TRUE(b.host.last.drives_enabled);
}

TEST(ControlLoop, DrainBusStopsAtItsPerCycleBoundOnAFloodedBus) {
  AppBench b;
  CanFrame junk;
  junk.id = 0x7FF;  // no CANopen node of ours
  junk.dlc = 0;
  const int flood = 3 * ControlLoop::kMaxFramesPerCycle + 10;
  for (int i = 0; i < flood; ++i) b.bus.inject_to_receiver(junk);
  const auto queued = static_cast<int>(b.bus.pending());  // the flood and the devices' boot-ups
  ASSERT_GE(queued, flood);
  b.loop->drain_bus(0);
  EXPECT_EQ(b.loop->status().drain_limited_cycles, 1U);
  EXPECT_EQ(static_cast<int>(b.bus.pending()), queued - ControlLoop::kMaxFramesPerCycle) << "the rest waits";
  b.loop->drain_bus(0);
  b.loop->drain_bus(0);
  b.loop->drain_bus(0);
  EXPECT_EQ(b.bus.pending(), 0U);
  EXPECT_EQ(b.loop->status().drain_limited_cycles, 3U);
}

TEST(ControlLoop, HostTableSwapsInAtAPeriodBoundary) {
  AppBench b;
  ASSERT_TRUE(b.start_running(bench_table(0.2)));
  const std::int64_t start_ns = b.loop->status().time_ns;
  for (int i = 0; i < 50; ++i) b.cycle();  // mid-period
  b.host.tables.push_back({7, bench_table(0.1, 0.95, 1.05)});
  b.cycle();
  EXPECT_TRUE(b.has_event(AppEventKind::table_accepted));
  EXPECT_EQ(b.host.last.table_ack_sequence, 7U);
  EXPECT_TRUE(b.loop->controller().has_pending_table()) << "not mid-period";
  ASSERT_TRUE(b.run_until([&] { return b.has_event(AppEventKind::table_swapped); }, 300));
  const AppEvent* swap = nullptr;
  for (const AppEvent& e : b.events) {
    if (e.kind == AppEventKind::table_swapped) swap = &e;
  }
  ASSERT_NE(swap, nullptr);
  const std::int64_t period_ns = 200'000'000;
  const std::int64_t into_period_ns = (swap->time_ns - start_ns) % period_ns;
  EXPECT_LT(into_period_ns, b.settings.period_ns) << "swapped in the first cycle of a period";
  EXPECT_EQ(b.loop->controller().active_table().period_s, 0.1);

  b.host.tables.push_back({8, bench_table(0.1, 0.2, 1.0)});  // below min rest length
  b.cycle();
  EXPECT_TRUE(b.has_event(AppEventKind::table_rejected));
  EXPECT_EQ(b.host.last.table_ack_sequence, 8U);
  EXPECT_NE(b.host.last.table_ack_error, core::TableError::none);
  EXPECT_EQ(b.loop->controller().active_table().period_s, 0.1) << "the previous table keeps running";
}

TEST(ControlLoop, CycleAllocatesNothing) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  b.drive0.controlwords.reserve(100'000);
  b.drive1.controlwords.reserve(100'000);
  std::vector<AppEvent> drained;
  drained.reserve(1000);
  for (int i = 0; i < 10; ++i) b.cycle();
  const tensegrity::test::AllocationScope scope;
  for (int i = 0; i < 2000; ++i) {
    b.bus.tick();
    b.loop->run_realtime_cycle();
    AppEvent e;
    while (b.loop->pop_event(e)) drained.push_back(e);
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_TRUE(b.running());
  EXPECT_GE(b.loop->status().cycles, 2000U);
}

TEST(ControlLoop, LockstepRunsExactlyOneCyclePerSyncAndSendsNone) {
  AppBench b(bench_settings(LoopMode::lockstep));
  const CanFrame sync = canopen::encode_sync();
  // No SYNC: no cycle, however long we wait.
  EXPECT_FALSE(b.loop->run_lockstep_cycle(1'000'000));
  EXPECT_EQ(b.loop->status().cycles, 0U);
  ASSERT_EQ(b.loop->load_table(bench_table()), core::TableError::none);
  for (int i = 0; i < 400 && !b.running(); ++i) {
    b.clock.advance_ns(1'000'000);
    b.bus.tick();
    b.bus.inject(sync);
    ASSERT_TRUE(b.loop->run_lockstep_cycle(1'000'000));
    EXPECT_FALSE(b.loop->run_lockstep_cycle(0)) << "one cycle per SYNC";
  }
  ASSERT_TRUE(b.running());
  const std::uint64_t cycles = b.loop->status().cycles;
  // Two SYNCs queued: two cycles, one each; time is ticks x period.
  b.bus.inject(sync);
  b.bus.inject(sync);
  EXPECT_TRUE(b.loop->run_lockstep_cycle(1'000'000));
  EXPECT_TRUE(b.loop->run_lockstep_cycle(1'000'000));
  EXPECT_FALSE(b.loop->run_lockstep_cycle(1'000'000));
  EXPECT_EQ(b.loop->status().cycles, cycles + 2);
  EXPECT_EQ(b.loop->status().time_ns, static_cast<std::int64_t>(cycles + 2) * b.settings.period_ns);
  EXPECT_EQ(b.bus.syncs_sent, 0U) << "the end cap must not produce SYNC in lockstep";
  EXPECT_EQ(b.loop->master().sync().received, cycles + 2);
  EXPECT_EQ(b.bus.flushes, b.loop->status().cycles) << "a batching bus sends once per cycle";
}

TEST(ControlLoop, FlushesTheBusOncePerCycleAfterItsLastFrame) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  const std::uint64_t cycles = b.loop->status().cycles;
  const std::uint64_t flushes = b.bus.flushes;
  const std::uint64_t syncs = b.bus.syncs_sent;
  for (int i = 0; i < 10; ++i) b.cycle();
  EXPECT_EQ(b.loop->status().cycles - cycles, 10U);
  EXPECT_EQ(b.bus.flushes - flushes, 10U);
  EXPECT_EQ(b.bus.syncs_sent - syncs, 10U) << "targets and SYNC before the flush";
}

}  // namespace
}  // namespace tensegrity::fw::app::test
