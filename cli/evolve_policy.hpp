// SPDX-License-Identifier: Apache-2.0
#pragma once
// `tensegrity evolve`'s output: the best team as a policy file, and the gait it plays.
#include "sim/model/episode.hpp"
#include "sim/evolve/coevolution.hpp"
#include "sim/evolve/config.hpp"
#include "robot/policy.hpp"

namespace tensegrity::cli {

// The best team as a policy file, with how it was made.
sim::Policy best_policy(const sim::Robot& robot, const sim::evolve::EvolveConfig& config,
                        const sim::evolve::Coevolution& evo, double score_m);

// The gait's strut spin and ground contacts, from one more episode of the policy
// through the control core at the robot's own step: every learned gait reports whether
// it rolls or skates. A policy learned at another step is scored with this episode, so
// that its file holds what `tensegrity sim` replays.
sim::EpisodeResult play_gait(const sim::Robot& robot, const sim::evolve::EvolveConfig& config, sim::Policy& policy);

}  // namespace tensegrity::cli
