// SPDX-License-Identifier: Apache-2.0
#pragma once
// What a run leaves, as text to compare bit for bit: its curve, its final state (as a
// checkpoint writes it) and its best team; and a short run of real physics to compare. The determinism, randomization and MPI
// checks each run a configuration twice and compare these.
#include <string>

#include "sim/evolve/checkpoint.hpp"
#include "sim/evolve/curve_csv.hpp"
#include "sim/evolve/driver.hpp"
#include "sim/evolve/episode_evaluator.hpp"

namespace tensegrity::sim::evolve::testing {

struct RunOutcome {
  std::string curve;
  std::string state;
  BestTeam best;
};

inline RunOutcome run_outcome(const EvolveConfig& config, Evaluator& evaluator) {
  auto result = drive(config, evaluator, {});
  return RunOutcome{curve_csv(result.evolution.curve()), checkpoint_to_json(config, result.evolution.state()),
                    result.evolution.best()};
}

// Two generations of four teams, 2 s episodes of real physics on `robot`: a run in seconds.
inline EvolveConfig short_physics_config(const Robot& robot) {
  EvolveConfig config;
  config.teams = 4;
  config.episodes = 8;
  config.population = 4;
  config.replace = 2;
  config.complexity = 3;
  config.period_s = 1.0;
  config.duration_s = 2.0;
  config.seed = 5;
  set_robot(config, robot);
  return config;
}

}  // namespace tensegrity::sim::evolve::testing
