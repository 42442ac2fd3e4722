// SPDX-License-Identifier: Apache-2.0
// A run depends on its seed alone: 1, 2 or 3 worker threads give the same curve,
// the same best team and the same final state, bit for bit.
#include <gtest/gtest.h>

#include "sim/evolve/checkpoint.hpp"
#include "sim/evolve/curve_csv.hpp"
#include "sim/evolve/driver.hpp"
#include "sim/evolve/episode_evaluator.hpp"
#include "robot/robot.hpp"
#include "tests/sim/evolve/synthetic.hpp"

#include "tests/sim/evolve/run_outcome.hpp"

namespace tensegrity::sim::evolve {
namespace {

using Outcome = testing::RunOutcome;

Outcome run(const EvolveConfig& config, Evaluator& evaluator) { return testing::run_outcome(config, evaluator); }

void expect_same(const Outcome& a, const Outcome& b) {
  EXPECT_EQ(a.curve, b.curve);
  EXPECT_EQ(a.state, b.state);
  EXPECT_EQ(a.best.team.rest_lengths_m, b.best.team.rest_lengths_m);
  EXPECT_EQ(a.best.score_m, b.best.score_m);
}

TEST(Determinism, SyntheticFitnessIsTheSameOnOneTwoAndThreeThreads) {
  const EvolveConfig config = testing::synthetic_config(FitnessMethod::historical, 1000, 11);
  std::vector<Outcome> outcomes;
  for (int threads : {1, 2, 3}) {
    ParallelEvaluator evaluator(testing::synthetic_score, threads);
    EXPECT_EQ(evaluator.threads(), threads);
    outcomes.push_back(run(config, evaluator));
  }
  expect_same(outcomes[0], outcomes[1]);
  expect_same(outcomes[0], outcomes[2]);
  // And a different seed is a different run.
  ParallelEvaluator evaluator(testing::synthetic_score, 2);
  EXPECT_NE(run(testing::synthetic_config(FitnessMethod::historical, 1000, 12), evaluator).curve, outcomes[0].curve);
}

TEST(Determinism, PhysicsIsTheSameOnOneTwoAndThreeThreads) {
  const Robot robot = load_robot(robot_path_named("superball"));
  const EvolveConfig config = testing::short_physics_config(robot);
  std::vector<Outcome> outcomes;
  for (int threads : {1, 2, 3}) {
    auto evaluator = make_episode_evaluator(robot, config, threads);
    outcomes.push_back(run(config, *evaluator));
  }
  expect_same(outcomes[0], outcomes[1]);
  expect_same(outcomes[0], outcomes[2]);
  EXPECT_TRUE(outcomes[0].best.found);
  // The recorded best score is what the policy scores when evaluated again alone.
  const TeamResult again =
      evaluate_team(robot, config.period_s, config.complexity, config.duration_s, config.dt_s, outcomes[0].best.team);
  EXPECT_EQ(again.score_m, outcomes[0].best.score_m);
  EXPECT_EQ(again.feasible, outcomes[0].best.feasible);
}

TEST(Determinism, EvaluatorErrorsReachTheCaller) {
  ParallelEvaluator evaluator(
      [](const Team& team) -> TeamResult {
        if (team.rest_lengths_m[0][0] > 0.9) throw std::runtime_error("boom");
        return TeamResult{};
      },
      2);
  EXPECT_THROW(run(testing::synthetic_config(FitnessMethod::historical, 200), evaluator), std::runtime_error);
}

}  // namespace
}  // namespace tensegrity::sim::evolve
