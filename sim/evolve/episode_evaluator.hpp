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

// The step a run on `robot` scores teams at when no other is asked for, as
// EvolveConfig::dt_s: the robot's learning step, or 0 when that is its own step (so
// that such a run and its checkpoints are what they were before the field existed).
double default_learning_dt_s(const Robot& robot);

// The robot's early end (learning.early_end) as the config's.
void set_default_early_end(EvolveConfig& config, const Robot& robot);

// One episode of `duration_s` from the settled start. Thread-safe.
// dt_s 0: the robot's own step. An episode ended by `early_end` scores
// early_end_score_m.
TeamResult evaluate_team(const Robot& robot, double period_s, int complexity, double duration_s, double dt_s,
                         const Team& team, const EarlyEnd& early_end = {});

// One episode of `controller` (made for `robot`) from the settled start, scored as
// evaluate_team scores it. Thread-safe for distinct controllers.
TeamResult score_episode(const Robot& robot, Controller& controller, double duration_s, double dt_s,
                         const EarlyEnd& early_end);

// What an episode ended early scores: its distance so far scaled to the whole
// duration (a steady gait's own score), at most the bar it provably cannot reach.
double early_end_score_m(const EpisodeResult& result, double duration_s, double bar_m);

// evaluate_team with the config's episode settings, as a thread-safe function that
// keeps its own copy of the robot. Throws ConfigError when the robot does not fit the
// config. Every evaluator of episodes (threads, MPI ranks) scores with this.
TeamFunction episode_team_function(const Robot& robot, const EvolveConfig& config);

// The episode scorer on `threads` workers (each worker runs whole episodes); with a
// randomization in the config, a RandomizedEvaluator (randomized_evaluator.hpp).
std::unique_ptr<Evaluator> make_episode_evaluator(const Robot& robot, const EvolveConfig& config, int threads);

}  // namespace tensegrity::sim::evolve
