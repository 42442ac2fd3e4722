// SPDX-License-Identifier: Apache-2.0
#pragma once
// An evolution's output: the best team as a policy file, and the gait it plays.
#include "sim/model/episode.hpp"
#include "sim/evolve/coevolution.hpp"
#include "sim/evolve/config.hpp"
#include "robot/policy.hpp"

namespace tensegrity::sim::evolve {

// The best team as a policy file, with how it was made.
Policy best_policy(const Robot& robot, const EvolveConfig& config, const Coevolution& evo, double score_m);

// The gait's strut spin and ground contacts, from one more episode of the policy
// through the control core at the robot's own step: every learned gait reports whether
// it rolls or skates. A policy learned at another step is scored with this episode, so
// that its file holds what `tensegrity sim` replays.
EpisodeResult play_gait(const Robot& robot, const EvolveConfig& config, Policy& policy);

}  // namespace tensegrity::sim::evolve
