// SPDX-License-Identifier: Apache-2.0
#pragma once
// What another rank needs to score teams exactly as rank 0 would: the robot
// description's text (so ranks need no shared file system, and cannot pick up a
// different file) with its hash, and the episode settings. The rank rebuilds the
// same TeamFunction from it (episode_team_function), hence the same scores.
#include <string>

#include "sim/evolve/config.hpp"
#include "sim/evolve/evaluator.hpp"
#include "sim/evolve/mpi_wire.hpp"
#include "robot/robot.hpp"

namespace tensegrity::sim::evolve {

// The `kind` of a setup for physics episodes.
inline constexpr const char* kEpisodeSetupKind = "tensegrity-episode/2";

struct EpisodeSetup {
  std::string robot_json;  // the description's text as read (the hash covers its content)
  std::string robot_hash;
  int cables = 0;
  double period_s = 0.0;
  int complexity = 0;
  double duration_s = 0.0;
  double dt_s = 0.0;  // 0: the robot's own step
};

// Throws ConfigError when `robot_json` is not the robot the config was made for.
EpisodeSetup episode_setup(const std::string& robot_json, const EvolveConfig& config);

wire::Setup to_wire(const EpisodeSetup& setup);
// Throws wire::WireError for another kind or damaged bytes.
EpisodeSetup episode_setup_from_wire(const wire::Setup& setup);

// Parses the robot, checks its hash and cable count (ConfigError, RobotError) and
// returns the scorer rank 0 uses for the same config.
TeamFunction episode_team_function(const EpisodeSetup& setup);

}  // namespace tensegrity::sim::evolve
