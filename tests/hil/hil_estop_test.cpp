// SPDX-License-Identifier: Apache-2.0
// An operator's emergency stop of a HIL run is the operator's to undo: an end cap
// killed and started again afterwards comes up idle, in both modes, instead of
// being set moving by the launcher beside eleven stopped end caps (its new life
// knows nothing of the stop its previous one took). The estop lands before the kill,
// or while the killed program is being started again.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <ostream>
#include <string>
#include <thread>

#include "ground/command.hpp"
#include "ground/station.hpp"
#include "tests/hil/hil_test_support.hpp"

namespace tensegrity::hil {

namespace {

using namespace hil_test;

constexpr int kDomain = 204;  // unique per DDS test: ctest runs tests in parallel

enum class When { before_kill, while_restarting };

struct EstopCase {
  StepperMode mode;
  When when;
};

void PrintTo(const EstopCase& c, std::ostream* os) {
  *os << to_string(c.mode) << (c.when == When::before_kill ? ", estop before the kill" : ", estop while restarting");
}

// The operator: one `tensegrity estop` to all twelve, once `go()` says so. Its tool
// re-sends it until every end cap acks, so an end cap restarting meanwhile gets it
// once its new program is on the link.
class Operator {
 public:
  explicit Operator(std::function<bool(const ground::Station&)> go) : go_(std::move(go)), thread_([this] { run(); }) {}
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
    while (!stop_) {
      if (go_(station)) {
        ground::CommandOptions co;
        co.endcap_mask = static_cast<std::uint16_t>((1U << 12) - 1U);
        co.timeout_s = 20.0;
        accepted_ = ground::send_command(station, ground::CommandKind::emergency_stop, 0, co).all_accepted();
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  std::function<bool(const ground::Station&)> go_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> accepted_{false};
  std::thread thread_;
};

bool all_playing(const ground::Station& station) {
  int playing = 0;
  for (const auto& s : station.snapshot()) playing += s.have_telemetry && s.telemetry.mode() == 1 ? 1 : 0;
  return playing == 12;
}

class HilEstop : public ::testing::TestWithParam<EstopCase> {};

TEST_P(HilEstop, AnEndcapRestartedAfterAnOperatorsEstopStaysIdle) {
  const EstopCase c = GetParam();
  if (c.mode == StepperMode::realtime) TENSEGRITY_SKIP_REAL_TIME_UNDER_ASAN();
  const bool before = c.when == When::before_kill;
  // While restarting: time for the new program to join the link and ack the estop.
  HilOptions o = options(before ? 14.0 : 20.0, Provision::dds);
  o.mode = c.mode;
  o.dds_domain = kDomain;
  o.max_speed = 1.0;  // lockstep at the wall clock's pace, as an operator lives
  o.scenario.events = kill_and_restart(4, 8.0, 8.5);
  std::atomic<bool> killed{false};
  HilResult r;
  bool accepted = false;
  bool estop_after_kill = false;
  {
    // Before the kill: the operator hears all twelve playing within about a second of
    // the start. While restarting: between the kill (8 s) and the restart (8.5 s).
    Operator op(before ? std::function<bool(const ground::Station&)>(all_playing)
                       : [&killed](const ground::Station&) { return killed.load(); });
    o.after_step = [&](const WorldStepper& s, ProcessLauncher&) {
      const double t = s.stats().sim_time_s();
      if (t >= 8.05) killed = true;
      // Needed before the kill in that case: if a loaded host made it late, say so
      // instead of failing on what follows from it.
      if (before && t >= 8.0 && !op.estop_accepted()) estop_after_kill = true;
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
  // Lockstep while restarting decides at the spawn, 0.45 s after the estop: the
  // launcher has heard it by then on any sane host, but the new program's own
  // estop is what keeps it still if not (docs/hil.md, "Left open").
  if (before || c.mode == StepperMode::realtime) {
    EXPECT_TRUE(idle) << ::testing::PrintToString(r.log);
  }
  EXPECT_EQ(r.playing, 0) << ::testing::PrintToString(r.log);
  for (const auto& e : r.endcaps) EXPECT_FALSE(e.playing) << "end cap " << e.endcap << " moves after the estop";
  // Before the kill the new program never heard of the estop: idle, not stopped.
  // While restarting the operator's tool re-sent it until the new program acked it.
  EXPECT_EQ(r.endcaps.at(4).fault, before ? "none" : "emergency stop");
  EXPECT_EQ(r.endcaps.at(3).fault, "emergency stop");
  EXPECT_TRUE(child_pids().empty());
}

INSTANTIATE_TEST_SUITE_P(Modes, HilEstop,
                         ::testing::Values(EstopCase{StepperMode::lockstep, When::before_kill},
                                           EstopCase{StepperMode::realtime, When::before_kill},
                                           EstopCase{StepperMode::lockstep, When::while_restarting},
                                           EstopCase{StepperMode::realtime, When::while_restarting}),
                         [](const ::testing::TestParamInfo<EstopCase>& i) {
                           return std::string(to_string(i.param.mode)) +
                                  (i.param.when == When::before_kill ? "_before_kill" : "_while_restarting");
                         });

}  // namespace
}  // namespace tensegrity::hil
