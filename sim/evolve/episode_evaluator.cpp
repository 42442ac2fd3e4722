// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/episode_evaluator.hpp"

#include "sim/model/core_controller.hpp"

namespace tensegrity::sim::evolve {

Policy team_policy(const Robot& robot, double period_s, int complexity, const Team& team) {
  Policy policy;
  policy.robot = robot.name;
  policy.period_s = period_s;
  policy.complexity = complexity;
  policy.cables.reserve(team.rest_lengths_m.size());
  for (std::size_t c = 0; c < team.rest_lengths_m.size(); ++c) {
    policy.cables.push_back(CablePolicy{static_cast<int>(c), robot.cables.at(c).owner, team.rest_lengths_m[c]});
  }
  policy.provenance.robot_hash = robot.hash;
  return policy;
}

TeamResult evaluate_team(const Robot& robot, double period_s, int complexity, double duration_s, double dt_s,
                         const Team& team) {
  const Policy policy = team_policy(robot, period_s, complexity, team);
  CoreController controller(robot, policy);
  EpisodeOptions options;
  options.duration_s = duration_s;
  options.dt_s = dt_s;
  options.start = StartKind::settled;
  const EpisodeResult result = run_episode(robot, controller, options);
  return TeamResult{result.feasible ? result.distance_m : 0.0, result.feasible};
}

void set_robot(EvolveConfig& config, const Robot& robot) {
  config.cables = robot.cable_count();
  config.min_rest_length_m = robot.motor.min_rest_length_m;
  config.max_rest_length_m = robot.motor.max_rest_length_m;
  config.robot_name = robot.name;
  config.robot_hash = robot.hash;
}

TeamFunction episode_team_function(const Robot& robot, const EvolveConfig& config) {
  if (robot.cable_count() != config.cables) {
    throw ConfigError("robot has " + std::to_string(robot.cable_count()) + " cables, config " +
                      std::to_string(config.cables));
  }
  // The robot is copied into the function: workers share it read-only.
  auto shared = std::make_shared<const Robot>(robot);
  const double period_s = config.period_s;
  const int complexity = config.complexity;
  const double duration_s = config.duration_s;
  const double dt_s = config.dt_s;
  return [shared, period_s, complexity, duration_s, dt_s](const Team& team) {
    return evaluate_team(*shared, period_s, complexity, duration_s, dt_s, team);
  };
}

std::unique_ptr<Evaluator> make_episode_evaluator(const Robot& robot, const EvolveConfig& config, int threads) {
  return std::make_unique<ParallelEvaluator>(episode_team_function(robot, config), threads);
}

}  // namespace tensegrity::sim::evolve
