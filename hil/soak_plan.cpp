// SPDX-License-Identifier: Apache-2.0
#include "hil/soak_plan.hpp"

#include <algorithm>
#include <random>
#include <string>

#include "hil/hil_error.hpp"

namespace tensegrity::hil {

namespace {

ScenarioEvent at(double time_s, int endcap, FaultKind fault) {
  ScenarioEvent e;
  e.time_s = time_s;
  e.endcap = endcap;
  e.fault = fault;
  return e;
}

// The generator's state: the events so far, and until when each end cap (and the
// whole robot, for the episodes that touch all twelve) is busy with one.
class Planner {
 public:
  explicit Planner(const SoakPlanOptions& o)
      : o_(o), rng_(o.seed), busy_(o.motors.size(), 0.0), end_s_(o.duration_s - o.quiet_end_s) {}

  Scenario plan() {
    std::exponential_distribution<double> gap(1.0 / o_.mean_gap_s);
    // Kills and operator estops the most: they are the paths by which a stop is lost.
    std::discrete_distribution<int> pick({3.0, 2.0, 1.0, 2.0, 3.0});
    for (double t = o_.quiet_start_s + gap(rng_); t < end_s_; t += gap(rng_)) {
      episode(static_cast<SoakEpisode>(pick(rng_)), t);
    }
    sort_events(out_);
    return out_;
  }

 private:
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }

  // A random end cap free at `t`, or -1.
  int free_endcap(double t) {
    std::vector<int> free;
    for (std::size_t e = 0; e < busy_.size(); ++e)
      if (busy_[e] <= t) free.push_back(static_cast<int>(e));
    if (free.empty()) return -1;
    return free[std::uniform_int_distribution<std::size_t>(0, free.size() - 1)(rng_)];
  }

  void add(double t, int endcap, FaultKind fault, int motor = 0) {
    ScenarioEvent e = at(t, endcap, fault);
    e.params.motor = motor;
    out_.events.push_back(e);
  }

  // The operator brings stopped end caps back: clear their fault, then start them.
  double clear_and_start(double t, int endcap) {
    add(t, endcap, FaultKind::clear_fault);
    add(t + 0.5, endcap, FaultKind::start);
    return t + 1.5;
  }

  void episode(SoakEpisode kind, double t) {
    const bool all = kind == SoakEpisode::cut_all || kind == SoakEpisode::estop;
    if (all && all_busy_ > t) return;
    const int e = all ? -1 : free_endcap(t);
    if (!all && e < 0) return;
    double until = t;
    switch (kind) {
      case SoakEpisode::kill_restart: {
        const double back = t + uniform(0.5, 4.0);
        if (back > end_s_) return;
        add(t, e, FaultKind::kill_endcap);
        add(back, e, FaultKind::restart_endcap);
        until = back + o_.settle_s;
        break;
      }
      case SoakEpisode::cut_one:
      case SoakEpisode::cut_all: {
        const double back = t + uniform(1.5, 4.0);
        if (back + 2.0 > end_s_) return;
        add(t, e, FaultKind::cut_dds);
        add(back, e, FaultKind::restore_dds);
        until = clear_and_start(back + 1.5, e);
        break;
      }
      case SoakEpisode::reboot_drive: {
        const int motor = std::uniform_int_distribution<int>(0, o_.motors[static_cast<std::size_t>(e)] - 1)(rng_);
        add(t, e, FaultKind::reboot_drive, motor);
        until = clear_and_start(t + uniform(1.0, 3.0), e);
        break;
      }
      case SoakEpisode::estop:
        add(t, -1, FaultKind::estop);
        until = clear_and_start(t + uniform(1.0, 3.0), -1);
        break;
    }
    if (all) {
      all_busy_ = until;
      for (double& b : busy_) b = std::max(b, until);
    } else {
      busy_[static_cast<std::size_t>(e)] = until;
    }
  }

  const SoakPlanOptions& o_;
  std::mt19937_64 rng_;
  std::vector<double> busy_;
  double all_busy_ = 0.0;
  double end_s_;
  Scenario out_;
};

}  // namespace

Scenario make_soak_scenario(const SoakPlanOptions& options) {
  if (options.motors.empty()) throw HilError("soak: the robot has no end caps");
  for (std::size_t e = 0; e < options.motors.size(); ++e) {
    if (options.motors[e] < 1) throw HilError("soak: end cap " + std::to_string(e) + " has no motors");
  }
  if (!(options.duration_s > options.quiet_start_s + options.quiet_end_s)) {
    throw HilError("soak: duration_s must exceed quiet_start_s + quiet_end_s (" +
                   std::to_string(options.quiet_start_s + options.quiet_end_s) + " s)");
  }
  if (!(options.mean_gap_s > 0.0)) throw HilError("soak: mean_gap_s must be > 0");
  return Planner(options).plan();
}

nlohmann::json scenario_json(const Scenario& scenario) {
  nlohmann::json events = nlohmann::json::array();
  for (const ScenarioEvent& ev : scenario.events) {
    nlohmann::json e{{"time_s", ev.time_s}, {"fault", to_string(ev.fault)}};
    if (ev.endcap >= 0) e["endcap"] = ev.endcap;
    if (ev.fault == FaultKind::reboot_drive) e["params"] = {{"motor", ev.params.motor}};
    events.push_back(e);
  }
  return {{"format", "tensegrity-hil-scenario/1"}, {"events", events}};
}

SoakTimeline::SoakTimeline(const Scenario& scenario, int endcap_count, double settle_s)
    : down_(static_cast<std::size_t>(endcap_count)), settle_s_(settle_s) {
  constexpr double kOpen = 1e300;  // down to the end
  for (const ScenarioEvent& ev : scenario.events) {
    const bool down = ev.fault == FaultKind::kill_endcap || ev.fault == FaultKind::cut_dds;
    const bool up = ev.fault == FaultKind::restart_endcap || ev.fault == FaultKind::restore_dds;
    if (!down && !up) continue;
    const bool cut = ev.fault == FaultKind::cut_dds || ev.fault == FaultKind::restore_dds;
    for (int e = 0; e < endcap_count; ++e) {
      if (ev.endcap >= 0 && ev.endcap != e) continue;
      auto& windows = down_[static_cast<std::size_t>(e)];
      if (down) {
        windows.push_back({ev.time_s, kOpen, cut});
      } else {
        // Closes the latest open window of the same sort.
        for (auto it = windows.rbegin(); it != windows.rend(); ++it) {
          if (it->cut == cut && it->to_s == kOpen) {
            it->to_s = ev.time_s;
            break;
          }
        }
      }
    }
  }
}

bool SoakTimeline::must_reach(int endcap, double t_s) const {
  for (const Window& w : down_.at(static_cast<std::size_t>(endcap))) {
    if (t_s >= w.from_s && t_s < w.to_s + settle_s_) return false;
  }
  return true;
}

int SoakTimeline::cuts_of(int endcap) const {
  const auto& windows = down_.at(static_cast<std::size_t>(endcap));
  return static_cast<int>(std::count_if(windows.begin(), windows.end(), [](const Window& w) { return w.cut; }));
}

}  // namespace tensegrity::hil
