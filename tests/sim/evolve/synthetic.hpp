// SPDX-License-Identifier: Apache-2.0
#pragma once
// A cheap fitness whose optimum is known, for testing the coevolution without
// physics: score = 10 - sum of squared distances of every value from a per-cable,
// per-subinterval target. The best team scores 10 with every value on its target.
#include <vector>

#include "sim/evolve/config.hpp"
#include "sim/evolve/evaluator.hpp"

namespace tensegrity::sim::evolve::testing {

inline double synthetic_target(std::size_t cable, std::size_t j) {
  // Spread over [0.7, 1.0], well inside the default limits [0.6, 1.1].
  return 0.7 + 0.03 * static_cast<double>((cable * 7 + j * 3) % 11);
}

inline TeamResult synthetic_score(const Team& team) {
  double sum = 0.0;
  for (std::size_t c = 0; c < team.rest_lengths_m.size(); ++c) {
    for (std::size_t j = 0; j < team.rest_lengths_m[c].size(); ++j) {
      const double d = team.rest_lengths_m[c][j] - synthetic_target(c, j);
      sum += d * d;
    }
  }
  return TeamResult{10.0 - sum, true};
}

inline EvolveConfig synthetic_config(FitnessMethod method, std::int64_t episodes, std::uint64_t seed = 7) {
  EvolveConfig c;
  c.method = method;
  c.episodes = episodes;
  c.seed = seed;
  // The paper's Algorithm 1 sizes (the author's Config.ini), not the CLI's default:
  // what these tests expect of selection and learning was derived for them.
  c.population = 10;
  c.replace = 5;
  c.cables = 24;
  c.complexity = 2;
  c.sigma_m = 0.01;
  c.robot_name = "synthetic";
  c.robot_hash = "0000000000000000";
  return c;
}

}  // namespace tensegrity::sim::evolve::testing
