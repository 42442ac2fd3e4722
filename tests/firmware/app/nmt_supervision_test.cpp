// SPDX-License-Identifier: Apache-2.0
// The end cap's supervision of its nodes' NMT state: a node that leaves operational
// after bring-up while still beating is a latched fault, found from its heartbeat
// within one producer period; and bring-up sets that producer period itself (0x1017)
// instead of living with each device's factory default.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <initializer_list>

#include "app_bench.hpp"

namespace tensegrity::fw::app::test {
namespace {

using canopen::Cia402State;
using canopen::NmtState;
using canopen::PowerRequest;
using core::FaultCause;

// The worst case from the node's state change to the quick stop being sent: the
// next heartbeat comes within one producer period, and the cycle that reads it
// latches the fault and sends the quick stop, at most one loop period later.
std::int64_t safe_state_bound_ns(const AppBench& b) {
  return std::int64_t{b.settings.master.node_heartbeat_period_ms} * 1'000'000 + b.settings.period_ns;
}

// Runs until the loop latches a fault; returns the time from `left_ns` to then.
std::int64_t time_to_fault_ns(AppBench& b, std::int64_t left_ns) {
  EXPECT_TRUE(b.run_until([&] { return b.loop->controller().fault() != FaultCause::none; }, 500));
  return b.clock.now_ns() - left_ns;
}

void expect_quick_stopped(AppBench& b) {
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::node_not_operational);
  EXPECT_EQ(b.loop->controller().mode(), core::Mode::faulted);
  EXPECT_EQ(b.loop->master().power_request(), PowerRequest::quick_stop);
  EXPECT_EQ(b.host.last.fault, FaultCause::node_not_operational) << "reported in telemetry";
}

TEST(NmtSupervision, ADriveDroppingToPreOperationalIsLatchedWithinOneProducerPeriod) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  for (int i = 0; i < 50; ++i) b.cycle();
  const std::int64_t left_ns = b.clock.now_ns();
  b.drive1.leave_operational(NmtState::pre_operational);
  const std::int64_t took_ns = time_to_fault_ns(b, left_ns);
  expect_quick_stopped(b);
  EXPECT_LE(took_ns, safe_state_bound_ns(b));
  EXPECT_TRUE(b.loop->master().drive_heartbeat(1).alive) << "still beating: not a lost heartbeat";
  std::printf("MEASURE drive pre-operational -> quick stop sent: %.1f ms (bound %.1f ms)\n",
              static_cast<double>(took_ns) * 1e-6, static_cast<double>(safe_state_bound_ns(b)) * 1e-6);
  b.cycle();
  EXPECT_EQ(b.drive0.state(), Cia402State::quick_stop_active) << "the other drive stops with it";
  for (int i = 0; i < 100; ++i) b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::node_not_operational) << "latched";
}

TEST(NmtSupervision, AStoppedLoadCellIsLatched) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  for (int i = 0; i < 50; ++i) b.cycle();
  const std::int64_t left_ns = b.clock.now_ns();
  b.load_cell.leave_operational(NmtState::stopped);
  const std::int64_t took_ns = time_to_fault_ns(b, left_ns);
  expect_quick_stopped(b);
  EXPECT_LE(took_ns, safe_state_bound_ns(b));
}

TEST(NmtSupervision, AClearBringsTheNodeBackToOperational) {
  AppBench b;
  ASSERT_TRUE(b.start_running());
  b.drive0.leave_operational(NmtState::stopped);
  ASSERT_TRUE(b.run_until([&] { return b.loop->controller().fault() != FaultCause::none; }, 500));
  b.host.commands.push_back({CommandKind::clear_fault, 0});
  ASSERT_TRUE(b.run_until([&] { return b.loop->drives_enabled(); }, 500))
      << to_string(b.loop->master().bring_up_step()) << " " << b.loop->master().bring_up_failure();
  for (int i = 0; i < 100; ++i) b.cycle();
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::none);
  EXPECT_EQ(b.drive0.nmt_state(), NmtState::operational);
}

// A device whose factory default (1 s) is longer than the end cap's heartbeat
// timeout (0.1 s) would be reported lost between every two beats.
TEST(NmtSupervision, BringUpWritesEachNodesHeartbeatPeriodAndTheHeartbeatFollowsIt) {
  AppBench b;
  for (sim::SimNode* n : std::initializer_list<sim::SimNode*>{&b.drive0, &b.drive1, &b.load_cell}) {
    n->script.heartbeat_period_ns = 1'000'000'000;
  }
  ASSERT_TRUE(b.start_running());
  const std::int64_t written_ns = std::int64_t{b.settings.master.node_heartbeat_period_ms} * 1'000'000;
  ASSERT_GT(written_ns, 0);
  EXPECT_EQ(b.drive0.heartbeat_period_ns(), written_ns);
  EXPECT_EQ(b.drive1.heartbeat_period_ns(), written_ns);
  EXPECT_EQ(b.load_cell.heartbeat_period_ns(), written_ns);
  // The master hears each drive at the written period: the gaps between the
  // heartbeats it reads stay within one period plus the loop's own.
  std::int64_t last_ns = b.loop->master().drive_heartbeat(0).last_seen_ns;
  std::int64_t widest_ns = 0;
  int beats = 0;
  for (int i = 0; i < 2000; ++i) {
    b.cycle();
    const std::int64_t seen_ns = b.loop->master().drive_heartbeat(0).last_seen_ns;
    if (seen_ns == last_ns) continue;
    widest_ns = std::max(widest_ns, seen_ns - last_ns);
    last_ns = seen_ns;
    ++beats;
  }
  EXPECT_LE(widest_ns, written_ns + b.settings.period_ns);
  EXPECT_GE(beats, static_cast<int>(2000 * b.settings.period_ns / (written_ns + b.settings.period_ns)));
  EXPECT_EQ(b.loop->controller().fault(), FaultCause::none);
  EXPECT_TRUE(b.running());
}

}  // namespace
}  // namespace tensegrity::fw::app::test
