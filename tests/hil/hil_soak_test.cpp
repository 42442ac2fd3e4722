// SPDX-License-Identifier: Apache-2.0
// The chaos soak's scenario and invariants without processes: the same seed gives the
// same scenario, its events are well formed and paired, the timeline says which end
// caps an estop must reach, and each invariant's check fails on a made-up breach.
#include <gtest/gtest.h>

#include <map>

#include "hil/hil_error.hpp"
#include "hil/soak_check.hpp"
#include "hil/soak_plan.hpp"

namespace tensegrity::hil {
namespace {

SoakPlanOptions plan_options(std::uint64_t seed, double duration_s = 600.0) {
  SoakPlanOptions o;
  o.seed = seed;
  o.duration_s = duration_s;
  o.motors.assign(12, 2);
  return o;
}

std::map<FaultKind, int> counts(const Scenario& s) {
  std::map<FaultKind, int> n;
  for (const auto& e : s.events) ++n[e.fault];
  return n;
}

TEST(HilSoakPlan, TheSeedDecidesTheScenario) {
  const Scenario a = make_soak_scenario(plan_options(7));
  const Scenario b = make_soak_scenario(plan_options(7));
  const Scenario c = make_soak_scenario(plan_options(8));
  ASSERT_EQ(a.events.size(), b.events.size());
  for (std::size_t i = 0; i < a.events.size(); ++i) EXPECT_EQ(a.events[i].describe(), b.events[i].describe());
  bool differs = a.events.size() != c.events.size();
  for (std::size_t i = 0; !differs && i < a.events.size(); ++i)
    differs = a.events[i].describe() != c.events[i].describe();
  EXPECT_TRUE(differs);
}

TEST(HilSoakPlan, EveryKindOfEpisodeWithinTheQuietTimesAndPaired) {
  const SoakPlanOptions o = plan_options(3);
  const Scenario s = make_soak_scenario(o);
  auto n = counts(s);
  for (FaultKind k : {FaultKind::kill_endcap, FaultKind::cut_dds, FaultKind::reboot_drive, FaultKind::estop,
                      FaultKind::clear_fault, FaultKind::start})
    EXPECT_GT(n[k], 0) << to_string(k);
  EXPECT_EQ(n[FaultKind::kill_endcap], n[FaultKind::restart_endcap]);
  EXPECT_EQ(n[FaultKind::cut_dds], n[FaultKind::restore_dds]);
  EXPECT_EQ(n[FaultKind::clear_fault], n[FaultKind::start]);
  for (std::size_t i = 0; i < s.events.size(); ++i) {
    const ScenarioEvent& e = s.events[i];
    EXPECT_GE(e.time_s, o.quiet_start_s) << e.describe();
    EXPECT_LE(e.time_s, o.duration_s - o.quiet_end_s) << e.describe();
    if (i > 0) {
      EXPECT_LE(s.events[i - 1].time_s, e.time_s) << "sorted";
    }
    if (e.fault == FaultKind::reboot_drive) {
      EXPECT_LT(e.params.motor, 2);
    }
  }
  // Each kill is followed by that end cap's restart before anything else is done to it.
  std::map<int, bool> down;
  for (const auto& e : s.events) {
    if (e.endcap < 0) continue;
    if (e.fault == FaultKind::kill_endcap) {
      EXPECT_FALSE(down[e.endcap]) << e.describe();
      down[e.endcap] = true;
    } else if (e.fault == FaultKind::restart_endcap) {
      EXPECT_TRUE(down[e.endcap]) << e.describe();
      down[e.endcap] = false;
    } else {
      EXPECT_FALSE(down[e.endcap]) << "done to a killed end cap: " << e.describe();
    }
  }
}

TEST(HilSoakPlan, TheScenarioFileReadsBackAsTheSame) {
  const Scenario a = make_soak_scenario(plan_options(5));
  const Scenario b = parse_scenario(scenario_json(a).dump(), 12);
  ASSERT_EQ(a.events.size(), b.events.size());
  for (std::size_t i = 0; i < a.events.size(); ++i) EXPECT_EQ(a.events[i].describe(), b.events[i].describe());
}

TEST(HilSoakPlan, OptionsItCannotPlanAreRefused) {
  SoakPlanOptions o = plan_options(1, 10.0);
  EXPECT_THROW(make_soak_scenario(o), HilError) << "shorter than the quiet times";
  o = plan_options(1);
  o.motors.clear();
  EXPECT_THROW(make_soak_scenario(o), HilError);
}

ScenarioEvent ev(double t, int e, FaultKind f) {
  ScenarioEvent x;
  x.time_s = t;
  x.endcap = e;
  x.fault = f;
  return x;
}

Scenario downs() {
  Scenario s;
  s.events = {ev(10, 3, FaultKind::kill_endcap), ev(12, 3, FaultKind::restart_endcap),
              ev(20, -1, FaultKind::cut_dds),    ev(22, -1, FaultKind::restore_dds),
              ev(40, 5, FaultKind::cut_dds),     ev(41, 5, FaultKind::restore_dds)};
  return s;
}

TEST(HilSoakTimeline, AnEstopMustReachTheEndCapsRunningAndSettledOnTheLink) {
  const SoakTimeline t(downs(), 12, 5.0);
  EXPECT_TRUE(t.must_reach(3, 9.9));
  EXPECT_FALSE(t.must_reach(3, 11.0)) << "killed";
  EXPECT_FALSE(t.must_reach(3, 16.9)) << "restarted, settling";
  EXPECT_TRUE(t.must_reach(3, 17.1));
  EXPECT_FALSE(t.must_reach(0, 21.0)) << "the host's link cut";
  EXPECT_TRUE(t.must_reach(0, 27.5));
  EXPECT_TRUE(t.must_reach(4, 40.5));
  EXPECT_FALSE(t.must_reach(5, 40.5));
  EXPECT_EQ(t.cuts_of(5), 2) << "its own and the host's";
  EXPECT_EQ(t.cuts_of(3), 1);
}

TEST(HilSoakCheck, EachInvariantFailsOnItsBreach) {
  const SoakTimeline t(downs(), 12, 5.0);
  SoakBounds b;
  b.estop_s = 0.05;
  SoakChecker c(t, 12, b);
  c.tension(1.0, 450.0);
  EXPECT_TRUE(c.violations().empty());
  c.tension(2.0, 501.0);
  c.tension(3.0, 502.0);
  ASSERT_EQ(c.violations().size(), 1u) << "once";
  EXPECT_EQ(c.violations()[0].invariant, "tension");
  std::vector<SoakAck> acks(12, SoakAck{true, 0.01});
  acks[3] = SoakAck{};      // killed at 11 s: not required
  acks[7].latency_s = 0.2;  // too late
  acks[8] = SoakAck{};      // never
  c.estop(11.0, acks);
  ASSERT_EQ(c.violations().size(), 3u);
  EXPECT_EQ(c.violations()[1].describe(), "estop at 11.000 s, end cap 7: acknowledged after 200.0 ms, bound 50.0 ms");
  EXPECT_EQ(c.violations()[2].endcap, 8);
  EXPECT_EQ(c.violations()[2].detail, "never acknowledged (running, on the link); no heartbeat of it heard");
  c.table(5.0, 0, 1, "gait", 2, 0.0);
  c.table(5.0, 1, 9, "", 0, 1.0);  // a new life, not yet loaded
  EXPECT_EQ(c.violations().size(), 3u);
  c.table(6.0, 1, 9, "", 0, 4.0);      // lost
  c.table(6.2, 1, 9, "", 0, 4.2);      // said once per life
  c.table(6.0, 2, 4, "gait", 1, 9.0);  // mixed
  ASSERT_EQ(c.violations().size(), 5u);
  EXPECT_EQ(c.violations()[4].detail, "plays gait v1, the run's is gait v2");
  c.host_losses(5, 2);
  c.host_losses(6, 2);
  ASSERT_EQ(c.violations().size(), 6u);
  EXPECT_EQ(c.violations()[5].describe(), "host_loss, end cap 6: 2 host loss(es), only 1 cut(s) of its link");
  c.run_failed("boom");
  const nlohmann::json j = c.to_json();
  EXPECT_EQ(j["invariants"]["estop"]["violations"], 2);
  EXPECT_EQ(j["invariants"]["table"]["violations"], 2);
  EXPECT_EQ(j["violations"].size(), 7u);
}

std::vector<RssSample> series(double seconds, std::int64_t start, std::int64_t per_s) {
  std::vector<RssSample> out;
  for (int i = 0; i <= static_cast<int>(seconds); ++i) out.push_back({double(i), start + per_s * i});
  return out;
}

TEST(HilSoakCheck, MemoryMustStayFlatOnceWarm) {
  const SoakTimeline t(Scenario{}, 12, 5.0);
  SoakChecker c(t, 12, SoakBounds{});
  c.memory("flat", series(120, 50 << 20, 0));
  c.memory("short", series(50, 50 << 20, 1 << 20));  // too short a life to judge
  EXPECT_TRUE(c.violations().empty());
  c.memory("leak", series(120, 50 << 20, 100 << 10));  // 100 KiB/s: ~8 MiB after warm-up
  ASSERT_EQ(c.violations().size(), 1u);
  EXPECT_EQ(c.violations()[0].invariant, "memory");
  EXPECT_NE(c.violations()[0].detail.find("leak grew"), std::string::npos) << c.violations()[0].detail;
  const auto [a, b] = rss_start_end(series(120, 1000, 10), SoakBounds{});
  EXPECT_EQ(a, 1000 + 10 * 32) << "mean of 30..34 s";
  EXPECT_EQ(b, 1000 + 10 * 118);
}

}  // namespace
}  // namespace tensegrity::hil
