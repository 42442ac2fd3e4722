// SPDX-License-Identifier: Apache-2.0
#pragma once
// Scores a team the way the paper does: the team becomes a policy, the policy is
// played by the firmware's control core (CoreController) on the ODE model for one
// episode from rest, and the score is the distance the centre moved; 0 when the
// episode went infeasible.
#include <memory>

#include "sim/model/episode.hpp"
#include "sim/evolve/config.hpp"
#include "sim/evolve/evaluator.hpp"
#include "robot/policy.hpp"
#include "robot/robot.hpp"

namespace tensegrity::sim::evolve {

// The team as a policy file for `robot` (owners from the robot; provenance empty).
Policy team_policy(const Robot& robot, double period_s, int complexity, const Team& team);

// Fills what the config takes from the robot: cable count, rest-length limits, name
// and hash (checkpoints and MPI ranks compare them).
void set_robot(EvolveConfig& config, const Robot& robot);

// One episode of `duration_s` from the settled start. Thread-safe.
// dt_s 0: the robot's own step.
TeamResult evaluate_team(const Robot& robot, double period_s, int complexity, double duration_s, double dt_s,
                         const Team& team);

// evaluate_team with the config's episode settings, as a thread-safe function that
// keeps its own copy of the robot. Throws ConfigError when the robot does not fit the
// config. Every evaluator of episodes (threads, MPI ranks) scores with this.
TeamFunction episode_team_function(const Robot& robot, const EvolveConfig& config);

// The episode scorer on `threads` workers (each worker runs whole episodes).
std::unique_ptr<Evaluator> make_episode_evaluator(const Robot& robot, const EvolveConfig& config, int threads);

}  // namespace tensegrity::sim::evolve
