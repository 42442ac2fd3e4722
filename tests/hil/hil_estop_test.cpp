// SPDX-License-Identifier: Apache-2.0
// An operator's emergency stop of a HIL run is the operator's to undo: an end cap
// killed and started again afterwards comes up idle, in both modes, instead of
// being set moving by the launcher beside eleven stopped end caps (its new life
// knows nothing of the stop its previous one took).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <ostream>
#include <string>
#include <thread>

#include "ground/command.hpp"
#include "ground/station.hpp"
#include "tests/hil/hil_test_support.hpp"

namespace tensegrity::hil {

// For the test names ctest lists (otherwise "1-byte object <00>").
void PrintTo(StepperMode mode, std::ostream* os) { *os << to_string(mode); }

namespace {

using namespace hil_test;

constexpr int kDomain = 204;  // unique per DDS test: ctest runs tests in parallel

// The operator: once all twelve end caps report playing, one `tensegrity estop`.
class Operator {
 public:
  Operator() : thread_([this] { run(); }) {}
  ~Operator() {
    stop_ = true;
    thread_.join();
  }
  bool estop_accepted() const { return accepted_; }

 private:
  void run() {
    ground::StationOptions so;
    so.domain = kDomain;
    so.name = "operator";
    so.publish_heartbeat = false;  // a bystander: not the end caps' host
    so.serve_time = false;
    ground::Station station(so);
    const auto all = static_cast<std::uint16_t>((1U << 12) - 1U);
    while (!stop_) {
      int playing = 0;
      for (const auto& s : station.snapshot()) playing += s.have_telemetry && s.telemetry.mode() == 1 ? 1 : 0;
      if (playing == 12) {
        ground::CommandOptions co;
        co.endcap_mask = all;
        co.timeout_s = 5.0;
        accepted_ = ground::send_command(station, ground::CommandKind::emergency_stop, 0, co).all_accepted();
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  std::atomic<bool> stop_{false};
  std::atomic<bool> accepted_{false};
  std::thread thread_;
};

class HilEstop : public ::testing::TestWithParam<StepperMode> {};

TEST_P(HilEstop, AnEndcapRestartedAfterAnOperatorsEstopStaysIdle) {
  const StepperMode mode = GetParam();
  if (mode == StepperMode::realtime) TENSEGRITY_SKIP_REAL_TIME_UNDER_ASAN();
  HilOptions o = options(14.0, Provision::dds);
  o.mode = mode;
  o.dds_domain = kDomain;
  o.max_speed = 1.0;  // lockstep at the wall clock's pace: the estop lands long before the kill
  // The operator hears all twelve playing within about a second of the start.
  o.scenario.events = kill_and_restart(4, 8.0, 8.5);
  HilResult r;
  bool accepted = false;
  bool estop_after_kill = false;
  {
    Operator op;
    // What this test is about needs the estop in before the kill: if a loaded host
    // made it late, say so instead of failing on what follows from it.
    o.after_step = [&op, &estop_after_kill](const WorldStepper& s, ProcessLauncher&) {
      if (s.stats().sim_time_s() >= 8.0 && !op.estop_accepted()) estop_after_kill = true;
    };
    r = run_hil(o);
    accepted = op.estop_accepted();
  }
  ASSERT_TRUE(r.ok) << r.error;
  ASSERT_TRUE(accepted) << "the operator's estop was not taken by all twelve";
  ASSERT_FALSE(estop_after_kill) << "the operator's estop was acked only after the kill at 8 s (a slow host?)";
  EXPECT_EQ(r.endcaps.at(4).restarts, 1u);
  bool idle = false;
  for (const auto& line : r.log) {
    EXPECT_EQ(line.find("end cap 4 back after a restart: started"), std::string::npos) << line;
    idle = idle || line.find("end cap 4 back after a restart: left idle") != std::string::npos;
  }
  EXPECT_TRUE(idle) << ::testing::PrintToString(r.log);
  EXPECT_EQ(r.playing, 0) << ::testing::PrintToString(r.log);
  for (const auto& e : r.endcaps) EXPECT_FALSE(e.playing) << "end cap " << e.endcap << " moves after the estop";
  EXPECT_EQ(r.endcaps.at(4).fault, "none") << "a new life: idle, not stopped";
  EXPECT_EQ(r.endcaps.at(3).fault, "emergency stop");
  EXPECT_TRUE(child_pids().empty());
}

INSTANTIATE_TEST_SUITE_P(Modes, HilEstop, ::testing::Values(StepperMode::lockstep, StepperMode::realtime),
                         [](const ::testing::TestParamInfo<StepperMode>& i) {
                           return std::string(to_string(i.param));
                         });

}  // namespace
}  // namespace tensegrity::hil
