// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/episode_evaluator.hpp"

#include <algorithm>

#include "sim/evolve/randomized_evaluator.hpp"
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
                         const Team& team, const EarlyEnd& early_end) {
  const Policy policy = team_policy(robot, period_s, complexity, team);
  CoreController controller(robot, policy);
  return score_episode(robot, controller, duration_s, dt_s, early_end);
}

TeamResult score_episode(const Robot& robot, Controller& controller, double duration_s, double dt_s,
                         const EarlyEnd& early_end) {
  EpisodeOptions options;
  options.duration_s = duration_s;
  options.dt_s = dt_s;
  options.start = StartKind::settled;
  options.early_end = early_end;
  const EpisodeResult result = run_episode(robot, controller, options);
  if (!result.feasible) return TeamResult{0.0, false};
  if (result.ended_early) return TeamResult{early_end_score_m(result, duration_s, early_end.bar_m), true};
  return TeamResult{result.distance_m, true};
}

double early_end_score_m(const EpisodeResult& result, double duration_s, double bar_m) {
  if (!(result.sim_time_s > 0.0)) return 0.0;
  return std::min(bar_m, result.distance_m * duration_s / result.sim_time_s);
}

void set_default_early_end(EvolveConfig& config, const Robot& robot) {
  config.early_end_bar_m = robot.early_end_bar_m;
  config.early_end_speed_m_per_s = robot.early_end_max_speed_m_per_s;
}

void set_robot(EvolveConfig& config, const Robot& robot) {
  config.cables = robot.cable_count();
  config.min_rest_length_m = robot.motor.min_rest_length_m;
  config.max_rest_length_m = robot.motor.max_rest_length_m;
  config.robot_name = robot.name;
  config.robot_hash = robot.hash;
}

double default_learning_dt_s(const Robot& robot) {
  return robot.learning_time_step_s == robot.time_step_s ? 0.0 : robot.learning_time_step_s;
}

TeamFunction episode_team_function(const Robot& robot, const EvolveConfig& config) {
  // A team's score on randomized models depends on the generation, which a function
  // of the team alone (threads, MPI ranks) does not know.
  if (!config.randomization.empty()) {
    throw ConfigError(
        "randomized models (--randomize) are scored on this process's threads only, not sent to MPI "
        "ranks: run without --mpi");
  }
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
  const EarlyEnd early_end{config.early_end_bar_m, config.early_end_speed_m_per_s};
  return [shared, period_s, complexity, duration_s, dt_s, early_end](const Team& team) {
    return evaluate_team(*shared, period_s, complexity, duration_s, dt_s, team, early_end);
  };
}

std::unique_ptr<Evaluator> make_episode_evaluator(const Robot& robot, const EvolveConfig& config, int threads) {
  if (!config.randomization.empty()) return std::make_unique<RandomizedEvaluator>(robot, config, threads);
  return std::make_unique<ParallelEvaluator>(episode_team_function(robot, config), threads);
}

}  // namespace tensegrity::sim::evolve
