// SPDX-License-Identifier: Apache-2.0
// The fault injector without processes or sockets: scenario events at physics
// times become actions on a recording target's devices, wire and programs, each
// in the step it is due, and timed frame faults end on time.
#include <gtest/gtest.h>

#include "firmware/drivers/nmt.hpp"
#include "hil/fault_injector.hpp"
#include "hil/hil_error.hpp"

namespace tensegrity::hil {
namespace {

constexpr double kDtS = 0.001;

class RecordingTarget final : public FaultTarget {
 public:
  RecordingTarget() {
    for (int e = 0; e < 3; ++e)
      devices_.emplace_back(e, std::vector<int>{2 * e, 2 * e + 1}, fw::SpoolGeometry{}, 1.1, true);
  }
  int endcap_count() const override { return static_cast<int>(devices_.size()); }
  EndcapDevices& devices(int e) override { return devices_.at(static_cast<std::size_t>(e)); }
  void send(int e, const FrameOut& frames) override {
    if (!frames.empty()) actions.push_back("send " + std::to_string(e) + " x" + std::to_string(frames.size()));
  }
  void set_drop(int e, double p) override { actions.push_back("drop " + std::to_string(e) + " " + std::to_string(p)); }
  void set_corrupt(int e, double p, CorruptKind) override {
    actions.push_back("corrupt " + std::to_string(e) + " " + std::to_string(p));
  }
  void kill(int e) override { actions.push_back("kill " + std::to_string(e)); }
  void restart(int e) override { actions.push_back("restart " + std::to_string(e)); }
  std::string set_dds_link(int e, bool up) override {
    actions.push_back(std::string(up ? "link up " : "link cut ") + std::to_string(e));
    return e == 1 ? "not running" : "";
  }
  std::string mute_dds(int e) override {
    actions.push_back("mute " + std::to_string(e));
    return "";
  }
  std::string freeze(int e, bool loop_only) override {
    actions.push_back(std::string(loop_only ? "hang " : "stop ") + std::to_string(e));
    return "";
  }
  std::string operator_command(const ScenarioEvent& e) override {
    actions.push_back(std::string(to_string(e.fault)) + " " + std::to_string(e.endcap));
    return e.fault == FaultKind::start ? "busy" : "";
  }
  std::vector<std::string> actions;

 private:
  std::vector<EndcapDevices> devices_;
};

ScenarioEvent event(double time_s, int endcap, FaultKind fault, FaultParams params = {}) {
  ScenarioEvent e;
  e.time_s = time_s;
  e.endcap = endcap;
  e.fault = fault;
  e.params = params;
  return e;
}

// Steps 0 .. last, returning the actions of each step that had any.
std::vector<std::pair<std::int64_t, std::vector<std::string>>> run(FaultInjector& injector, RecordingTarget& target,
                                                                   std::int64_t last, std::vector<std::string>& log) {
  std::vector<std::pair<std::int64_t, std::vector<std::string>>> by_step;
  for (std::int64_t step = 0; step <= last; ++step) {
    injector.apply_due(step, step * 1'000'000, target, log);
    if (!target.actions.empty()) by_step.emplace_back(step, std::move(target.actions));
    target.actions.clear();
  }
  return by_step;
}

TEST(HilFaultInjector, EventsBecomeActionsInTheStepTheyAreDue) {
  Scenario s;
  FaultParams drop;
  drop.probability = 0.5;
  drop.duration_s = 0.010;
  FaultParams corrupt;
  corrupt.probability = 0.25;
  s.events = {event(0.0, 2, FaultKind::load_cell_stuck),           event(0.005, 1, FaultKind::drop_frames, drop),
              event(0.005, 0, FaultKind::corrupt_frames, corrupt), event(0.020, 2, FaultKind::kill_endcap),
              event(0.0305, 2, FaultKind::restart_endcap),         event(0.040, -1, FaultKind::cut_dds)};
  FaultInjector injector(s, kDtS);
  RecordingTarget target;
  std::vector<std::string> log;
  const auto by_step = run(injector, target, 50, log);
  ASSERT_EQ(by_step.size(), 5u);
  EXPECT_EQ(by_step[0].first, 5);
  EXPECT_EQ(by_step[0].second, (std::vector<std::string>{"drop 1 0.500000", "corrupt 0 0.250000"}));
  EXPECT_EQ(by_step[1].first, 15) << "the drop's 10 ms are over";
  EXPECT_EQ(by_step[1].second, (std::vector<std::string>{"drop 1 0.000000"}));
  EXPECT_EQ(by_step[2].first, 20);
  EXPECT_EQ(by_step[2].second, (std::vector<std::string>{"kill 2"}));
  EXPECT_EQ(by_step[3].first, 31) << "30.5 ms: the first step at or after it";
  EXPECT_EQ(by_step[3].second, (std::vector<std::string>{"restart 2"}));
  EXPECT_EQ(by_step[4].first, 40);
  EXPECT_EQ(by_step[4].second, (std::vector<std::string>{"link cut 0", "link cut 1", "link cut 2"}))
      << "no end cap: every end cap's link";
  EXPECT_TRUE(target.devices(2).summary().load_cell_stuck) << "applied at step 0";
  ASSERT_EQ(log.size(), 6u);
  EXPECT_NE(log[5].find("not done for end cap 1: not running"), std::string::npos) << log[5];
}

// The parser takes any duration >= 0 JSON can write; one past any run is "to the end",
// not a step count from an out-of-range llround.
TEST(HilFaultInjector, ADurationPastAnyRunLastsToTheEnd) {
  Scenario s;
  FaultParams drop;
  drop.probability = 1.0;
  drop.duration_s = 1e300;
  s.events = {event(0.001, 1, FaultKind::drop_frames, drop)};
  FaultInjector injector(s, kDtS);
  RecordingTarget target;
  std::vector<std::string> log;
  const auto by_step = run(injector, target, 200, log);
  ASSERT_EQ(by_step.size(), 1u) << "started, never ended";
  EXPECT_EQ(by_step[0].second, (std::vector<std::string>{"drop 1 1.000000"}));
}

TEST(HilFaultInjector, AMuteReachesTheNamedEndcapOrEveryOne) {
  Scenario s;
  s.events = {event(0.002, 2, FaultKind::mute_dds), event(0.004, -1, FaultKind::mute_dds)};
  FaultInjector injector(s, kDtS);
  RecordingTarget target;
  std::vector<std::string> log;
  const auto by_step = run(injector, target, 5, log);
  ASSERT_EQ(by_step.size(), 2u);
  EXPECT_EQ(by_step[0].second, (std::vector<std::string>{"mute 2"}));
  EXPECT_EQ(by_step[1].second, (std::vector<std::string>{"mute 0", "mute 1", "mute 2"}));
  ASSERT_EQ(log.size(), 2u);
  EXPECT_NE(log[0].find("mute_dds"), std::string::npos) << log[0];
}

// The operator's commands go to the target as one event each (every end cap or one);
// one it cannot take is logged as not done.
TEST(HilFaultInjector, OperatorCommandsAreHandedOverWhenDue) {
  Scenario s;
  s.events = {event(0.001, -1, FaultKind::estop), event(0.003, 2, FaultKind::clear_fault),
              event(0.003, -1, FaultKind::start)};
  FaultInjector injector(s, kDtS);
  RecordingTarget target;
  std::vector<std::string> log;
  const auto by_step = run(injector, target, 4, log);
  ASSERT_EQ(by_step.size(), 2u);
  EXPECT_EQ(by_step[0].first, 1);
  EXPECT_EQ(by_step[0].second, (std::vector<std::string>{"estop -1"}));
  EXPECT_EQ(by_step[1].second, (std::vector<std::string>{"clear_fault 2", "start -1"}));
  ASSERT_EQ(log.size(), 3u);
  EXPECT_EQ(log[0], "t=0.001 s all end caps: estop");
  EXPECT_NE(log[2].find("start: not done: busy"), std::string::npos) << log[2];
}

TEST(HilFaultInjector, DeviceFaultsReachTheChosenMotors) {
  Scenario s;
  FaultParams m1;
  m1.motor = 1;
  FaultParams all;
  all.motor = -1;
  FaultParams released = m1;
  released.motor = 0;
  s.events = {event(0.001, 0, FaultKind::drive_fault, m1), event(0.001, 1, FaultKind::drive_silent, all),
              event(0.002, 2, FaultKind::release_spool, released), event(0.002, 2, FaultKind::seize_spool, m1)};
  FaultInjector injector(s, kDtS);
  RecordingTarget target;
  std::vector<std::string> log;
  const auto by_step = run(injector, target, 3, log);
  ASSERT_EQ(by_step.size(), 1u);
  EXPECT_EQ(by_step[0].first, 1);
  EXPECT_EQ(by_step[0].second, (std::vector<std::string>{"send 0 x1"})) << "the drive's EMCY, at once";
  EXPECT_EQ(target.devices(0).drive(1).emcy_sent(), 1u);
  EXPECT_EQ(target.devices(0).drive(0).emcy_sent(), 0u) << "motor 1 only";
  EXPECT_TRUE(target.devices(1).drive(0).script.silent);
  EXPECT_TRUE(target.devices(1).drive(1).script.silent);
  const std::vector<double> rest{1.0, 1.0, 1.0, 1.0, 0.9, 0.9};
  std::vector<double> preferred = rest;
  target.devices(2).preferred(rest, preferred);
  EXPECT_DOUBLE_EQ(preferred[4], 1.1) << "released: pays out to the longest rest length";
  EXPECT_DOUBLE_EQ(preferred[5], 0.9) << "seized: keeps its length";
}

// Each device booted and started by NMT, as the end cap's bring-up leaves it.
void start_nodes(EndcapDevices& d) {
  FrameOut out;
  const auto start = [&](SimNode& n) {
    n.boot(0, out);
    n.on_frame(fw::canopen::encode_nmt(fw::canopen::NmtCommand::start, n.node_id()), 0, out);
  };
  for (std::size_t m = 0; m < d.motor_count(); ++m) start(d.drive(m));
  start(d.load_cell());
}

TEST(HilFaultInjector, NodesLeaveOperationalAndGoOnBeating) {
  Scenario s;
  FaultParams m1;
  m1.motor = 1;
  s.events = {event(0.001, 0, FaultKind::drive_preoperational, m1), event(0.001, 1, FaultKind::load_cell_stopped)};
  FaultInjector injector(s, kDtS);
  RecordingTarget target;
  for (int e = 0; e < 2; ++e) start_nodes(target.devices(e));
  std::vector<std::string> log;
  (void)run(injector, target, 2, log);
  using fw::canopen::NmtState;
  EXPECT_EQ(target.devices(0).drive(1).nmt_state(), NmtState::pre_operational);
  EXPECT_EQ(target.devices(0).drive(0).nmt_state(), NmtState::operational) << "motor 1 only";
  EXPECT_EQ(target.devices(1).load_cell().nmt_state(), NmtState::stopped);
  EXPECT_TRUE(target.devices(1).load_cell().answering()) << "powered and beating, unlike a reboot or silence";
  FrameOut beats;
  target.devices(0).drive(1).tick(1'000'000'000, beats);
  ASSERT_EQ(beats.size(), 1U);
  EXPECT_EQ(beats[0].data[0], static_cast<std::uint8_t>(NmtState::pre_operational)) << "its heartbeat says so";
  ASSERT_EQ(log.size(), 2U);
  EXPECT_NE(log[0].find("drive_preoperational (motor 1)"), std::string::npos) << log[0];
}

TEST(HilFaultInjector, AMotorTheEndCapDoesNotHaveIsAnError) {
  Scenario s;
  FaultParams m3;
  m3.motor = 3;
  s.events = {event(0.0, 0, FaultKind::drive_fault, m3)};
  FaultInjector injector(s, kDtS);
  RecordingTarget target;
  std::vector<std::string> log;
  try {
    injector.apply_due(0, 0, target, log);
    FAIL() << "no error";
  } catch (const HilError& e) {
    EXPECT_NE(std::string(e.what()).find("end cap has no motor 3"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tensegrity::hil
