// SPDX-License-Identifier: Apache-2.0
#pragma once
// What a run leaves, as text to compare bit for bit: its curve, its final state (as a
// checkpoint writes it) and its best team. The determinism, randomization and MPI
// checks each run a configuration twice and compare these.
#include <string>

#include "sim/evolve/checkpoint.hpp"
#include "sim/evolve/curve_csv.hpp"
#include "sim/evolve/driver.hpp"

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

}  // namespace tensegrity::sim::evolve::testing
