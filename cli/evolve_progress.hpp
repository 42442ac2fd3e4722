// SPDX-License-Identifier: Apache-2.0
#pragma once
// The one-line progress display of an evolution on a terminal; silent otherwise so
// that logs and pipes get only the final report.
#include <chrono>
#include <cstdint>

#include "sim/evolve/coevolution.hpp"

namespace tensegrity::cli {

class EvolveProgress {
 public:
  EvolveProgress(bool enabled, std::int64_t episode_budget);
  // After each generation: generation, episodes, best, mean, infeasible %, rate, ETA.
  void update(const sim::evolve::Coevolution& evolution, const sim::evolve::GenerationStats& stats);
  // Ends the line (if one was drawn).
  void finish();

 private:
  bool enabled_;
  bool drawn_ = false;
  std::int64_t budget_;
  std::int64_t first_episodes_ = -1;  // episodes done before this process's first generation
  std::chrono::steady_clock::time_point started_;
};

}  // namespace tensegrity::cli
