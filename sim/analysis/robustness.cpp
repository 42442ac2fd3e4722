// SPDX-License-Identifier: Apache-2.0
#include "sim/analysis/robustness.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <numbers>
#include <thread>

#include "sim/analysis/faulty_controller.hpp"
#include "sim/model/core_controller.hpp"

namespace tensegrity::sim {
namespace {

EpisodeResult play(const Robot& robot, const Policy& policy, const HardwareFaults& faults, double duration_s) {
  CoreController core(robot, policy);
  FaultyController controller(core, faults);
  EpisodeOptions options;
  options.duration_s = duration_s;
  options.start = StartKind::settled;
  return run_episode(robot, controller, options);
}

void play_case(const Robot& robot, const Policy& policy, const PerturbationCase& c, const RobustnessReport& report,
               double duration_s, RobustnessCase& out) {
  out.name = c.name;
  try {
    const Robot changed = perturbed(robot, c, report.travel_azimuth_deg);
    out.robot_hash = changed.hash;
    const HardwareFaults faults{c.load_cell_noise_n, c.load_cell_bias_n, c.load_cell_seed, c.actuation_delay_s};
    out.episode = play(changed, policy, faults, duration_s);
    const double nominal = report.nominal.distance_m;
    const Eigen::Vector2d& d = out.episode.displacement_m;
    out.retention = nominal > 0.0 ? out.episode.distance_m / nominal : 0.0;
    if (c.slope_deg > 0.0) {
      const double a = changed.ground_slope_azimuth_deg * std::numbers::pi / 180.0;
      // Up the slope is against the direction it falls toward.
      out.uphill_m = -(d.x() * std::cos(a) + d.y() * std::sin(a));
      // On a slope a gait that rolls back down keeps nothing: what counts is the
      // progress the way it rolls on its own ground.
      const double t = report.travel_azimuth_deg * std::numbers::pi / 180.0;
      out.retention = nominal > 0.0 ? (d.x() * std::cos(t) + d.y() * std::sin(t)) / nominal : 0.0;
    }
  } catch (const std::exception& e) {
    out.error = e.what();
  }
}

}  // namespace

RobustnessReport run_robustness(const Robot& robot, const Policy& policy, const PerturbationSet& set,
                                const RobustnessOptions& options) {
  RobustnessReport report;
  report.nominal = play(robot, policy, HardwareFaults{}, options.duration_s);
  const Eigen::Vector2d& d = report.nominal.displacement_m;
  if (d.norm() > 0.0) report.travel_azimuth_deg = std::atan2(d.y(), d.x()) * 180.0 / std::numbers::pi;
  report.cases.resize(set.cases.size());
  std::atomic<std::size_t> next{0};
  const auto work = [&] {
    for (std::size_t i = next++; i < set.cases.size(); i = next++) {
      play_case(robot, policy, set.cases[i], report, options.duration_s, report.cases[i]);
    }
  };
  const int threads = std::clamp(options.threads, 1, static_cast<int>(std::max<std::size_t>(1, set.cases.size())));
  std::vector<std::jthread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  pool.clear();  // joins
  for (std::size_t i = 0; i < report.cases.size(); ++i) {
    const bool worse = report.worst < 0 || report.cases[i].retention < report.cases[report.worst].retention;
    if (worse) report.worst = static_cast<int>(i);
  }
  return report;
}

}  // namespace tensegrity::sim
