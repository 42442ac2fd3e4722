// SPDX-License-Identifier: Apache-2.0
#pragma once
// Runs a coevolution to its episode budget with the bookkeeping around it: a
// checkpoint after every generation, resuming from one, the curve CSV, and a hook
// for progress display. Shared by `tensegrity evolve`, `bench evolve` and the tests.
#include <filesystem>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "sim/evolve/coevolution.hpp"
#include "sim/evolve/config.hpp"
#include "sim/evolve/evaluator.hpp"

namespace tensegrity::sim::evolve {

struct DriverOptions {
  std::filesystem::path checkpoint_dir;  // empty: no checkpoints
  // Continue from the checkpoint in checkpoint_dir (a fresh start if there is none).
  // Without it an existing checkpoint is an error rather than silently overwritten.
  bool resume = false;
  std::filesystem::path curve_csv;  // empty: no CSV
  // Stop after this many generations in this call even if budget is left (tests,
  // benchmarks); < 0: run to the budget.
  int max_generations = -1;
  std::function<void(const Coevolution&, const GenerationStats&)> on_generation;
};

struct DriverResult {
  Coevolution evolution;
  bool resumed = false;
  int resumed_generation = 0;         // generations already done when resumed
  std::int64_t resumed_episodes = 0;  // episodes already done when resumed
  std::vector<std::string> warnings;  // e.g. a corrupt checkpoint skipped
};

DriverResult drive(const EvolveConfig& config, Evaluator& evaluator, const DriverOptions& options);

}  // namespace tensegrity::sim::evolve
