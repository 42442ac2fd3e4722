// SPDX-License-Identifier: Apache-2.0
// The HIL's DDS link: errors naming an end cap missing from the link, and the
// link cut and restored during the run. With --host-loss continue an open-loop
// gait does not notice (in lockstep the run is identical to an uncut one); with
// stop (the default) the end caps stop when they lose the host, latched as host_lost.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "ground/keystore.hpp"
#include "sim/model/core_controller.hpp"
#include "sim/model/episode.hpp"
#include "tests/hil/hil_test_support.hpp"

namespace tensegrity::hil {
namespace {

using namespace hil_test;

// The same policy for the same time, in-process: what an open-loop lockstep run must roll.
double in_process_m(const std::filesystem::path& policy, double duration_s) {
  sim::CoreController reference(robot(), sim::load_policy(policy, robot()));
  sim::EpisodeOptions eo;
  eo.duration_s = duration_s;
  return sim::run_episode(robot(), reference, eo).distance_m;
}

ScenarioEvent endcap_event(double time_s, int endcap, FaultKind fault) {
  ScenarioEvent e;
  e.time_s = time_s;
  e.endcap = endcap;  // -1: every end cap (DDS link faults only)
  e.fault = fault;
  return e;
}

ScenarioEvent link_event(double time_s, FaultKind fault) { return endcap_event(time_s, -1, fault); }

// A real-time run over DDS with one event.
HilOptions realtime_with(double duration_s, const ScenarioEvent& event) {
  HilOptions o = options(duration_s, Provision::dds);
  o.mode = StepperMode::realtime;
  o.scenario.events = {event};
  return o;
}

bool logged(const HilResult& r, const std::string& a, const std::string& b) {
  for (const auto& line : r.log) {
    if (line.find(a) != std::string::npos && line.find(b) != std::string::npos) return true;
  }
  return false;
}

// An end cap that never joins fails the run after the last of its fresh starts.
TEST(HilDds, AnEndCapMissingFromTheLinkIsNamed) {
  HilOptions o = options(1.0, Provision::dds);
  o.endcap_extra_args[7] = {"--no-dds"};  // boots on its bus, never joins DDS
  o.dds_discovery_timeout_s = 3.0;
  o.link_attempts = 2;
  const HilResult r = run_hil(o);
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.link_attempts, 2);
  EXPECT_TRUE(logged(r, "attempt 1 of 2 failed before the start", "end cap(s) 7")) << r.error;
  // End cap 7 and only it is named as silent. Within the short 3 s another end cap
  // may also still be syncing its clock (named in a second clause, after a comma):
  // that is not what this test is about, and under ctest it happened 2 runs in 3.
  const std::string silent = "no heartbeat from end cap(s) 7";
  const auto at = r.error.find(silent);
  ASSERT_NE(at, std::string::npos) << r.error;
  const char after = at + silent.size() < r.error.size() ? r.error[at + silent.size()] : ' ';
  EXPECT_TRUE(after == ' ' || after == ',') << "another end cap named as silent: " << r.error;
  EXPECT_TRUE(child_pids().empty());
}

// Fast DDS 2.9's secured discovery now and then leaves one end cap unmatched whichever
// ground station joins (docs/guide/security.md); the run then starts every process afresh.
// Here end cap 7 stays off DDS in the first attempt only.
TEST(HilDds, ALinkThatDoesNotComeUpStartsTheRunAfresh) {
  HilOptions o = options(1.0, Provision::dds);
  o.link_attempts = 2;
  std::vector<int> attempts;
  o.before_attempt = [&attempts](int attempt, HilOptions& a) {
    attempts.push_back(attempt);
    a.endcap_extra_args.clear();
    if (attempt == 1) a.endcap_extra_args[7] = {"--no-dds"};
    a.dds_discovery_timeout_s = attempt == 1 ? 3.0 : 40.0;
  };
  const HilResult r = run_hil(o);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.link_attempts, 2);
  EXPECT_EQ(attempts, (std::vector<int>{1, 2}));
  EXPECT_EQ(r.playing, 12);
  EXPECT_TRUE(logged(r, "attempt 1 of 2 failed before the start", "end cap(s) 7"));
  EXPECT_TRUE(child_pids().empty()) << "the first attempt's end caps left behind";
}

// `tensegrity hil --keystore DIR`: the ground station and the twelve end caps speak
// DDS Security with a keystore's enclaves. Open loop and lockstep, the secured
// link changes nothing the physics sees: the in-process distance, to the drives'
// position quantisation.
TEST(HilDds, ASecuredRunRollsAsTheSimulatorDoes) {
  const double duration_s = 4.0;
  const double ref_m = in_process_m(policy_file(), duration_s);

  HilOptions o = options(duration_s, Provision::dds);
  // One keystore for every run of this test on the machine, made on first use
  // (remade when an older version made it: its grants would refuse the end caps).
  o.dds_keystore = std::filesystem::temp_directory_path() / "tensegrity-hil-test-keystore";
  if (std::filesystem::exists(o.dds_keystore) && !ground::keystore_complete(o.dds_keystore)) {
    ground::KeystoreOptions replace;
    replace.replace = true;
    ground::create_keystore(o.dds_keystore, replace);
  }
  o.dds_discovery_timeout_s = 40.0;
  const HilResult r = run_hil(o);
  if (!r.ok) {
    for (const auto& line : r.log) std::printf("%s\n", line.c_str());
  }
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.playing, 12);
  EXPECT_NEAR(r.distance_m, ref_m, 1e-5 * ref_m);
  EXPECT_NE(r.provisioner.find("secured"), std::string::npos) << r.provisioner;
  EXPECT_EQ(r.provisioner.find("unsecured"), std::string::npos) << r.provisioner;
  for (const auto& line : r.log) {
    if (line.rfind("dds:", 0) == 0) std::printf("%s\n", line.c_str());
  }
  std::printf("secured HIL: %.3f m (in-process %.3f m)\n", r.distance_m, ref_m);
}

TEST(HilDds, LinkCutWithContinueKeepsTheGaitGoing) {
  const double duration_s = 50.0;
  const double ref_m = in_process_m(evolved_policy_file(), duration_s);

  HilOptions o = options(duration_s, Provision::dds);
  o.policy = evolved_policy_file();
  o.host_loss = "continue";
  // Long in physics time: the end caps judge host loss on the wall clock (1 s),
  // and lockstep runs several times faster than that.
  o.scenario.events = {link_event(2.0, FaultKind::cut_dds), link_event(42.0, FaultKind::restore_dds)};
  double at_cut = 0.0, at_restore = 0.0;
  o.after_step = [&](const WorldStepper& s, ProcessLauncher&) {
    if (s.step_index() == 2000) at_cut = s.travel().distance_m;
    if (s.step_index() == 42000) at_restore = s.travel().distance_m;
  };
  const HilResult r = run_hil(o);
  ASSERT_TRUE(r.ok) << r.error;
  for (const auto& e : r.endcaps) {
    EXPECT_EQ(e.link_cuts, 1U) << "end cap " << e.endcap;
    EXPECT_GE(e.host_losses, 1U) << "end cap " << e.endcap << " never noticed the host was gone";
    EXPECT_EQ(e.host_returns, e.host_losses) << "end cap " << e.endcap << " did not see the host come back";
    EXPECT_EQ(e.fault, "none") << "end cap " << e.endcap;
  }
  EXPECT_GT(at_restore, at_cut + 1.0) << "the gait kept rolling while the link was cut";
  // Open loop and lockstep: the physics never knew the link was gone (the same
  // run as in-process, up to the drives' position quantisation: ~1e-7 relative).
  EXPECT_NEAR(r.distance_m, ref_m, 1e-5 * ref_m);
  EXPECT_EQ(r.playing, 12);
  EXPECT_EQ(r.max_phase_offset_s, 0.0);
  std::printf("link cut, continue: %.3f m at the cut, %.3f m at the restore, %.3f m at the end (in-process %.3f m)\n",
              at_cut, at_restore, r.distance_m, ref_m);
}

// A one-way stall of one end cap's link (mute_dds: its participant stops sending
// and still hears, as a security handshake stalled one way leaves it): the host
// stops hearing end cap 5 and, when its lease on it runs out (20 s, Fast DDS's
// default, on the wall clock, hence real time), stops talking to it. End cap 5 joins
// again, after its unheard wait (20 s) or at that host loss, whichever comes first,
// and is heard again; the open-loop gait never knew: all twelve play to the end.
TEST(HilDds, AMutedEndcapJoinsAgainAndPlaysOn) {
  TENSEGRITY_SKIP_REAL_TIME_UNDER_ASAN();
  HilOptions o = realtime_with(36.0, endcap_event(2.0, 5, FaultKind::mute_dds));
  o.policy = evolved_policy_file();
  // What is under test is the rejoin: the host loss it may meet on the way (below)
  // must not stop the gait, so the end caps are told to continue.
  o.host_loss = "continue";
  const HilResult r = run_hil(o);
  ASSERT_TRUE(r.ok) << r.error;
  for (const auto& e : r.endcaps) {
    EXPECT_EQ(e.dds_rejoins, e.endcap == 5 ? 1U : 0U) << "end cap " << e.endcap;
    EXPECT_LE(e.host_losses, e.endcap == 5 ? 1U : 0U) << "end cap " << e.endcap;
    EXPECT_EQ(e.host_returns, e.host_losses) << "end cap " << e.endcap << " did not hear the host again";
    EXPECT_EQ(e.fault, "none") << "end cap " << e.endcap;
  }
  EXPECT_EQ(r.playing, 12);
  EXPECT_TRUE(logged(r, "end cap 5", "mute_dds")) << "the scenario's event in the run's log";
  // The host's side: it went without end cap 5's heartbeat once, from just before the
  // mute for its 20 s wait (or the host's 20 s lease) and a discovery; the run's log says when.
  const HostHearing& host = r.endcaps.at(5).host;
  EXPECT_EQ(host.unheard, 1U);
  EXPECT_GT(host.longest_unheard_s, 10.0);
  EXPECT_LT(host.longest_unheard_s, 25.0);
  EXPECT_TRUE(logged(r, "end cap 5 unheard by the host since", "s into the run")) << ::testing::PrintToString(r.log);
  EXPECT_TRUE(logged(r, "end cap 5 heard again at", "s unheard")) << ::testing::PrintToString(r.log);
  std::printf(
      "muted end cap 5 at 2 s: unheard by the host for %.1f s, rejoined once (host losses %llu), %.3f m in "
      "%.0f s\n",
      host.longest_unheard_s, static_cast<unsigned long long>(r.endcaps.at(5).host_losses), r.distance_m, o.duration_s);
}

// An end cap that dies is seen from the host's side too: killed 1 s into a 6 s
// real-time run and not started again, it is unheard from then to the end (the spell
// still open at the end counts to the end), and the run's log says since when.
TEST(HilDds, AKilledEndcapIsUnheardByTheHostToTheEnd) {
  TENSEGRITY_SKIP_REAL_TIME_UNDER_ASAN();
  const HilResult r = run_hil(realtime_with(6.0, endcap_event(1.0, 4, FaultKind::kill_endcap)));
  ASSERT_TRUE(r.ok) << r.error;
  const HostHearing& host = r.endcaps.at(4).host;
  EXPECT_EQ(host.unheard, 1U);
  EXPECT_GT(host.unheard_s, 3.5);  // from its last heartbeat, about 1 s in, to the end at 6 s
  EXPECT_LT(host.unheard_s, 8.0);
  EXPECT_EQ(host.longest_unheard_s, host.unheard_s);
  EXPECT_TRUE(logged(r, "end cap 4 unheard by the host since", "s into the run")) << ::testing::PrintToString(r.log);
  EXPECT_FALSE(logged(r, "end cap 4 heard again", "")) << ::testing::PrintToString(r.log);
  std::printf("killed end cap 4 at 1 s: unheard by the host for the last %.1f s\n", host.unheard_s);
}

// The counts travel in each end cap's --stats-json, and a killed program's last
// snapshot is kept: end cap 4's link cut happened to the incarnation killed after
// it, and the run's summary still has it.
TEST(HilDds, AKilledEndcapsLinkEventsAreKept) {
  HilOptions o = options(8.0, Provision::dds);
  o.scenario.events = {link_event(0.5, FaultKind::cut_dds), link_event(4.0, FaultKind::restore_dds)};
  for (const ScenarioEvent& e : kill_and_restart(4, 5.0, 5.5)) o.scenario.events.push_back(e);
  const HilResult r = run_hil(o);
  ASSERT_TRUE(r.ok) << r.error;
  for (const auto& e : r.endcaps) {
    EXPECT_EQ(e.link_cuts, 1U) << "end cap " << e.endcap;
    EXPECT_EQ(e.restarts, e.endcap == 4 ? 1U : 0U) << "end cap " << e.endcap;
  }
}

TEST(HilDds, LinkCutWithStopStopsTheGait) {
  const double duration_s = 40.0;
  HilOptions o = options(duration_s, Provision::dds);
  o.policy = evolved_policy_file();
  o.host_loss = "stop";
  o.scenario.events = {link_event(2.0, FaultKind::cut_dds), link_event(38.0, FaultKind::restore_dds)};
  std::vector<double> distance_by_s;
  o.after_step = [&](const WorldStepper& s, ProcessLauncher&) {
    if (s.step_index() % 1000 == 0) distance_by_s.push_back(s.travel().distance_m);
  };
  const HilResult r = run_hil(o);
  ASSERT_TRUE(r.ok) << r.error;
  for (const auto& e : r.endcaps) {
    EXPECT_EQ(e.link_cuts, 1U) << "end cap " << e.endcap;
    EXPECT_GE(e.host_losses, 1U) << "end cap " << e.endcap;
    EXPECT_FALSE(e.playing) << "end cap " << e.endcap << " still playing after losing the host";
    EXPECT_EQ(e.fault, "host link lost") << "the stop is latched until cleared: end cap " << e.endcap;
  }
  EXPECT_EQ(r.playing, 0);
  ASSERT_EQ(distance_by_s.size(), 40u);
  // Stopped (each end cap holds its cables) and settled well before the end.
  EXPECT_LT(std::abs(distance_by_s[39] - distance_by_s[29]), 0.05)
      << "still moving: " << ::testing::PrintToString(distance_by_s);
  std::printf("link cut, stop: distance at 2, 10, 20, 30, 40 s: %.3f %.3f %.3f %.3f %.3f m\n", distance_by_s[1],
              distance_by_s[9], distance_by_s[19], distance_by_s[29], distance_by_s[39]);
}

}  // namespace
}  // namespace tensegrity::hil
