// SPDX-License-Identifier: Apache-2.0
// CANopen supervision with twelve real `endcap` programs (lockstep): a drive that
// reboots, an end cap whose control loop hangs, an end cap that dies (SIGSTOP).
// Each must reach its safe state within 2 control periods of detection, and
// detection must be bounded by the configured heartbeat times; both are measured
// on the emulator's device clock (1 ms ticks) and printed as MEASURE lines.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "hil/hil_run.hpp"
#include "hil/process_launcher.hpp"
#include "tests/hil/hil_test_support.hpp"

namespace tensegrity::hil {
namespace {

using namespace hil_test;
using fw::canopen::Cia402State;

constexpr std::int64_t kPeriodNs = 1'000'000;     // the HIL's control period
constexpr std::int64_t kProducerNs = 10'000'000;  // end cap heartbeat (default config)
constexpr std::int64_t kConsumerNs = 50'000'000;  // drives' 0x1016 (default: 5 x producer)

double ms(std::int64_t ns) { return static_cast<double>(ns) * 1e-6; }

ScenarioEvent event(double time_s, int endcap, FaultKind fault, int motor = 0) {
  ScenarioEvent ev;
  ev.time_s = time_s;
  ev.endcap = endcap;
  ev.fault = fault;
  ev.params.motor = motor;
  return ev;
}

// Per physics step, what the drives of one end cap did.
struct DriveWatch {
  int endcap = 0;
  std::int64_t fault_step = -1;          // the step the scenario's fault was applied in
  std::int64_t safe_step[2] = {-1, -1};  // first step a drive was out of operation enabled
  void observe(const WorldStepper& s, bool fault_applied) {
    if (fault_applied && fault_step < 0) fault_step = s.step_index();
    for (int m = 0; m < 2; ++m) {
      if (fault_step >= 0 && safe_step[m] < 0 && s.devices(endcap).drive(m).state() != Cia402State::operation_enabled) {
        safe_step[m] = s.step_index();
      }
    }
  }
};

TEST(HilSupervision, RebootedDriveStopsTheEndCapWithinTwoPeriods) {
  HilOptions o = options(2.0);
  o.scenario.events.push_back(event(1.0, 3, FaultKind::reboot_drive, 0));
  DriveWatch w;
  w.endcap = 3;
  o.after_step = [&w](const WorldStepper& s, ProcessLauncher&) { w.observe(s, s.devices(3).drive(0).reboots() > 0); };
  const HilResult r = run_hil(o);
  ASSERT_TRUE(r.ok) << r.error;
  const EndcapSummary& e = r.endcaps.at(3);
  EXPECT_EQ(e.fault, "CANopen node rebooted");
  ASSERT_EQ(e.devices.drive_states.size(), 2u);
  EXPECT_EQ(e.devices.drive_states[0], "switch on disabled") << "back unpowered";
  EXPECT_EQ(e.devices.drive_states[1], "quick stop active") << "the healthy drive stopped by the end cap";
  ASSERT_GE(w.fault_step, 0);
  ASSERT_GE(w.safe_step[1], 0);
  // Detection is the boot-up itself (the end cap reads it in the cycle of the tick
  // it arrives in); the quick stop goes out in that cycle's RPDO1.
  const std::int64_t latency_periods = w.safe_step[1] - w.fault_step;
  EXPECT_LE(latency_periods, 2) << "safe state within 2 control periods of the boot-up";
  std::printf("MEASURE reboot_drive: boot-up at step %lld, other drive quick-stopped at step %lld: %lld period(s)\n",
              static_cast<long long>(w.fault_step), static_cast<long long>(w.safe_step[1]),
              static_cast<long long>(latency_periods));
  for (const auto& other : r.endcaps) {
    if (other.endcap != 3) {
      EXPECT_EQ(other.fault, "none") << "end cap " << other.endcap;
    }
  }
}

// What one end cap's drives knew at the last physics step (device clock), and
// the steps at which the scenario's fault was applied and each drive detected.
struct SilenceWatch {
  int endcap = 0;
  struct Drive {
    std::uint32_t losses = 0;
    std::int64_t last_heard_ns = 0, lost_ns = 0, left_enabled_ns = 0, lost_step = -1;
    Cia402State state = Cia402State::not_ready_to_switch_on;  // at the last physics step
  };
  Drive drives[2];
  std::int64_t fault_step = -1;
  void observe(const WorldStepper& s) {
    if (fault_step < 0 && !s.log().empty() &&
        s.log().back().find("end cap " + std::to_string(endcap)) != std::string::npos) {
      fault_step = s.step_index();
    }
    for (int m = 0; m < 2; ++m) {
      const auto& d = s.devices(endcap).drive(m);
      Drive& w = drives[m];
      if (w.lost_step < 0 && d.heartbeat_losses() > 0) w.lost_step = s.step_index();
      w.losses = d.heartbeat_losses();
      w.last_heard_ns = d.last_consumed_heartbeat_ns();
      w.lost_ns = d.heartbeat_lost_ns();
      w.left_enabled_ns = d.left_enabled_ns();
      w.state = d.state();
    }
  }
};

// Hung loop and dead end cap: the end cap falls silent on its bus; each of its
// drives finds out through its consumer heartbeat (0x1016) and quick-stops (0x6007).
void expect_drives_stop_by_themselves(const HilResult& r, const SilenceWatch& snap, int endcap, const char* what,
                                      std::int64_t consumer_ns = kConsumerNs) {
  ASSERT_TRUE(r.ok) << r.error;
  const EndcapSummary& e = r.endcaps.at(endcap);
  ASSERT_EQ(e.devices.drive_states.size(), 2u);
  for (int m = 0; m < 2; ++m) {
    const auto& d = snap.drives[m];
    // At the run's last physics step, not after it: a stopped end cap is continued
    // to be shut down, and its first cycles may command its drives again.
    EXPECT_EQ(d.state, Cia402State::quick_stop_active) << what << ": drive " << m;
    ASSERT_EQ(d.losses, 1u) << what << ": drive " << m << " never saw the heartbeat stop";
    ASSERT_GE(snap.fault_step, 0);
    const std::int64_t detection_ns = d.lost_ns - d.last_heard_ns;
    const std::int64_t safe_ns = d.left_enabled_ns - d.lost_ns;
    const std::int64_t since_fault_ns = (d.lost_step - snap.fault_step) * kPeriodNs;
    EXPECT_GT(detection_ns, consumer_ns);
    EXPECT_LE(detection_ns, consumer_ns + kPeriodNs) << "detection bounded by the consumer heartbeat time";
    EXPECT_GE(safe_ns, 0);
    EXPECT_LE(safe_ns, 2 * kPeriodNs) << "safe state within 2 control periods of detection";
    std::printf(
        "MEASURE %s end cap %d drive %d: last end-cap heartbeat -> detection %.1f ms (consumer %.0f ms, "
        "producer %.0f ms); detection -> quick stop %.1f ms; fault injected -> detection %.1f ms\n",
        what, endcap, m, ms(detection_ns), ms(consumer_ns), ms(kProducerNs), ms(safe_ns), ms(since_fault_ns));
  }
  for (const auto& other : r.endcaps) {
    if (other.endcap != endcap) {
      EXPECT_EQ(other.fault, "none") << "end cap " << other.endcap;
    }
  }
}

TEST(HilSupervision, HungLoopIsStoppedByItsDrivesAndSeenByTheHost) {
  HilOptions o = options(2.0);
  o.scenario.events.push_back(event(0.5, 5, FaultKind::hang_loop));
  SilenceWatch snap;
  snap.endcap = 5;
  bool stalled_logged = false;
  const bool dds = o.provision == Provision::dds;
  o.after_step = [&](const WorldStepper& s, ProcessLauncher& l) {
    snap.observe(s);
    if (s.step_index() != 1999 || !dds) return;
    // The DDS node's watchdog judges the loop on the wall clock (0.5 s): give it time.
    for (int i = 0; i < 300 && !stalled_logged; ++i) {
      stalled_logged = l.log_text(5).find("control loop STALLED") != std::string::npos;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  };
  const HilResult r = run_hil(o);
  expect_drives_stop_by_themselves(r, snap, 5, "hang_loop");
  if (dds) {
    EXPECT_TRUE(stalled_logged) << "the DDS node must withhold its heartbeat for a hung loop";
    EXPECT_GE(r.endcaps.at(5).loop_stalls, 1U);
  }
}

TEST(HilSupervision, DeadEndCapIsStoppedByItsDrives) {
  HilOptions o = options(2.0, Provision::local);
  o.scenario.events.push_back(event(0.5, 9, FaultKind::stop_endcap));
  SilenceWatch snap;
  snap.endcap = 9;
  o.after_step = [&](const WorldStepper& s, ProcessLauncher&) { snap.observe(s); };
  const HilResult r = run_hil(o);
  expect_drives_stop_by_themselves(r, snap, 9, "stop_endcap");
}

// Real time: the end caps run their own clocks and send SYNC; the stopped one just
// stops. No other end cap may trip on its own supervision meanwhile.
TEST(HilSupervision, DeadEndCapIsStoppedByItsDrivesInRealTime) {
  TENSEGRITY_SKIP_REAL_TIME_UNDER_ASAN();
  HilOptions o = options(2.0);
  o.mode = StepperMode::realtime;
  o.scenario.events.push_back(event(1.0, 9, FaultKind::stop_endcap));
  SilenceWatch snap;
  snap.endcap = 9;
  o.after_step = [&](const WorldStepper& s, ProcessLauncher&) { snap.observe(s); };
  const HilResult r = run_hil(o);
  expect_drives_stop_by_themselves(r, snap, 9, "stop_endcap (real time)",
                                   static_cast<std::int64_t>(kRealtimeConsumerHeartbeatS * 1e9));
}

}  // namespace
}  // namespace tensegrity::hil
