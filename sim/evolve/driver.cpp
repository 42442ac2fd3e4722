// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/driver.hpp"

#include "sim/evolve/checkpoint.hpp"
#include "sim/evolve/curve_csv.hpp"

namespace tensegrity::sim::evolve {
namespace {

DriverResult start(const EvolveConfig& config, const DriverOptions& options) {
  validate(config);
  if (options.checkpoint_dir.empty()) return DriverResult{Coevolution(config), false, 0, 0, {}};
  if (!options.resume) {
    if (checkpoint_exists(options.checkpoint_dir)) {
      throw CheckpointError(options.checkpoint_dir.string() +
                            " already holds a checkpoint: pass --resume to continue it, or choose another directory");
    }
    return DriverResult{Coevolution(config), false, 0, 0, {}};
  }
  auto loaded = load_checkpoint(options.checkpoint_dir, config);
  if (!loaded) return DriverResult{Coevolution(config), false, 0, 0, {}};
  const int generation = loaded->state.generation;
  const std::int64_t episodes = loaded->state.episodes;
  try {
    return DriverResult{Coevolution(config, std::move(loaded->state)), true, generation, episodes,
                        std::move(loaded->warnings)};
  } catch (const ConfigError& e) {
    throw CheckpointError(loaded->path.string() + ": " + e.what());
  }
}

}  // namespace

DriverResult drive(const EvolveConfig& config, Evaluator& evaluator, const DriverOptions& options) {
  DriverResult result = start(config, options);
  Coevolution& evo = result.evolution;
  // Rewritten on resume too: the CSV may be one generation behind the checkpoint.
  // Written before the first generation, so that a bad path fails now, not after it.
  if (!options.curve_csv.empty()) {
    if (options.curve_csv.has_parent_path()) std::filesystem::create_directories(options.curve_csv.parent_path());
    write_curve_csv(options.curve_csv, evo.curve());
  }
  for (int done_here = 0; !evo.done() && (options.max_generations < 0 || done_here < options.max_generations);
       ++done_here) {
    const GenerationStats stats = evo.step(evaluator);
    // Checkpoint before anything else: what is reported is never ahead of what is saved.
    if (!options.checkpoint_dir.empty()) save_checkpoint(options.checkpoint_dir, config, evo.state());
    if (!options.curve_csv.empty()) write_curve_csv(options.curve_csv, evo.curve());
    if (options.on_generation) options.on_generation(evo, stats);
  }
  return result;
}

}  // namespace tensegrity::sim::evolve
