// SPDX-License-Identifier: Apache-2.0
#pragma once
// How far a gait rolls when the robot is not the model it was learned in: the gait
// played on the robot as its file describes it (the nominal case), then on each case
// of a perturbation set (robot/perturbation_set.hpp), in parallel threads. Retention
// is a case's distance over the nominal one (on a slope, its progress the nominal way).
#include <optional>
#include <string>
#include <vector>

#include "robot/perturbation_set.hpp"
#include "robot/policy.hpp"
#include "sim/model/episode.hpp"

namespace tensegrity::sim {

struct RobustnessOptions {
  double duration_s = 60.0;
  int threads = 1;
};

struct RobustnessCase {
  std::string name;
  std::string robot_hash;  // of the perturbed model
  EpisodeResult episode;   // distance 0 when infeasible
  // Distance over the nominal distance; on a slope, the progress in the direction the
  // gait rolls nominally over the nominal distance (negative: it went back).
  double retention = 0.0;
  // Slope cases: the centre's progress up the slope (negative: it went down), m.
  std::optional<double> uphill_m;
  std::string error;  // the case could not be played (the episode did not run)
};

struct RobustnessReport {
  EpisodeResult nominal;
  double travel_azimuth_deg = 0.0;  // the way the gait rolls on the nominal ground
  std::vector<RobustnessCase> cases;
  int worst = -1;  // the case of least retention
};

RobustnessReport run_robustness(const Robot& robot, const Policy& policy, const PerturbationSet& set,
                                const RobustnessOptions& options);

}  // namespace tensegrity::sim
