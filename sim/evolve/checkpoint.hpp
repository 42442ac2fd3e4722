// SPDX-License-Identifier: Apache-2.0
#pragma once
// A run's checkpoint: DIR/checkpoint.json (format "tensegrity-evolve-checkpoint/1")
// holds the config and the whole CoevolutionState after a generation. Saving keeps
// the previous one as DIR/checkpoint.prev.json, so that a checkpoint damaged after
// the fact (disk, hand edits) costs one generation, not the run.
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/evolve/coevolution.hpp"
#include "sim/evolve/config.hpp"

namespace tensegrity::sim::evolve {

class CheckpointError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr const char* kCheckpointFile = "checkpoint.json";
inline constexpr const char* kPreviousCheckpointFile = "checkpoint.prev.json";

std::string checkpoint_to_json(const EvolveConfig& config, const CoevolutionState& state);
struct Checkpoint {
  EvolveConfig config;
  CoevolutionState state;
};
// Throws CheckpointError naming `source` for text that is not a complete checkpoint.
Checkpoint parse_checkpoint(const std::string& text, const std::string& source);

// Atomic; creates `dir` if needed.
void save_checkpoint(const std::filesystem::path& dir, const EvolveConfig& config, const CoevolutionState& state);

// True when `dir` holds a checkpoint file (current or previous), valid or not.
bool checkpoint_exists(const std::filesystem::path& dir);

struct LoadedCheckpoint {
  CoevolutionState state;
  std::filesystem::path path;         // the file used
  std::vector<std::string> warnings;  // e.g. the current file was corrupt
};
// The newest usable checkpoint in `dir`; nullopt when there is none. Throws
// CheckpointError when no file in it can be read, or when the one read was made with
// a config other than `expected` (the error lists the differing fields). A larger
// `episodes` than the checkpoint's is not a difference: the run goes on to the new
// budget (unless its last generation was cut short by the old one).
std::optional<LoadedCheckpoint> load_checkpoint(const std::filesystem::path& dir, const EvolveConfig& expected);

}  // namespace tensegrity::sim::evolve
