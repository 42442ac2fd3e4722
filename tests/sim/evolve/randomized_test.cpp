// SPDX-License-Identifier: Apache-2.0
// Robust learning: teams scored on sampled models. A run is its seed's to the bit,
// every team of a generation meets the same models, one zero-width sample is plain
// evolution, the settled starts of past generations leave the cache, and the run's
// randomization is part of its config (checkpoints) and refused by MPI ranks.
#include "sim/evolve/randomized_evaluator.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "robot/robot.hpp"
#include "sim/evolve/checkpoint.hpp"
#include "sim/evolve/curve_csv.hpp"
#include "sim/evolve/driver.hpp"
#include "sim/evolve/episode_evaluator.hpp"
#include "sim/evolve/episode_setup.hpp"
#include "sim/model/episode.hpp"
#include "sim/model/settled_cache.hpp"

#include "tests/sim/evolve/run_outcome.hpp"

namespace tensegrity::sim::evolve {
namespace {

using nlohmann::json;

json range(double lo, double hi) { return {{"min", lo}, {"max", hi}}; }

std::string ranges_text(json ranges) {
  return parse_randomization(json{{"format", kRandomizationFormat}, {"ranges", std::move(ranges)}}.dump()).canonical;
}

// With a delay the episodes go through the faulty-hardware controller.
EvolveConfig randomized(EvolveConfig config, int k, bool delay = true) {
  json ranges = {{"motor_speed_scale", range(0.8, 1.2)}, {"friction_scale", range(0.7, 1.4)}};
  if (delay) ranges["actuation_delay_s"] = range(0.0, 0.05);
  config.randomization = ranges_text(ranges);
  config.randomize_k = k;
  return config;
}

using Outcome = testing::RunOutcome;

Outcome run(const EvolveConfig& config, Evaluator& evaluator) { return testing::run_outcome(config, evaluator); }

const Robot& robot() {
  static const Robot r = load_robot(robot_path_named("superball-paper"));
  return r;
}

TEST(Randomized, TheScoreRules) {
  EXPECT_EQ(combine_sample_scores(SampleScore::mean, {1.0, 2.0, 6.0}), 3.0);
  EXPECT_EQ(combine_sample_scores(SampleScore::q25, {7.0}), 7.0);
  // Sorted 1 2 3 4 5: a quarter of the way is the second.
  EXPECT_EQ(combine_sample_scores(SampleScore::q25, {5.0, 1.0, 4.0, 2.0, 3.0}), 2.0);
  // Sorted 0 4 8 12: position 0.75, between 0 and 4.
  EXPECT_EQ(combine_sample_scores(SampleScore::q25, {12.0, 8.0, 4.0, 0.0}), 3.0);
}

TEST(Randomized, TheSameSeedIsTheSameRunToTheBitInAnyThreadCount) {
  const EvolveConfig config = randomized(testing::short_physics_config(robot()), 2);
  RandomizedEvaluator one(robot(), config, 1);
  RandomizedEvaluator two(robot(), config, 2);
  const Outcome a = run(config, one);
  const Outcome b = run(config, two);
  EXPECT_EQ(a.curve, b.curve);
  EXPECT_EQ(a.state, b.state);
  EvolveConfig other = config;
  other.seed = 6;
  RandomizedEvaluator three(robot(), other, 2);
  EXPECT_NE(run(other, three).curve, a.curve);
}

TEST(Randomized, TeamsOfOneGenerationMeetTheSameModelsAndTheNextNewOnes) {
  const EvolveConfig config = randomized(testing::short_physics_config(robot()), 3, false);
  RandomizedEvaluator evaluator(robot(), config, 2);
  evaluator.set_generation(4);
  std::vector<std::string> hashes;
  for (const Robot& m : evaluator.models()) hashes.push_back(m.hash);
  ASSERT_EQ(hashes.size(), 3U);
  Team team;
  team.rest_lengths_m.assign(static_cast<std::size_t>(config.cables), std::vector<double>{0.7, 0.9, 1.0});
  Team other = team;
  other.rest_lengths_m[0] = {1.0, 0.6, 0.8};
  // A team scores the same alone and in a batch, first or last: every team of the
  // generation is scored on the same models.
  const std::vector<Team> batch{team, other, team};
  const auto results = evaluator.evaluate(batch);
  const auto alone = evaluator.evaluate(std::vector<Team>{team});
  EXPECT_EQ(results[0].score_m, results[2].score_m);
  EXPECT_EQ(results[0].score_m, alone[0].score_m);
  std::vector<std::string> after;
  for (const Robot& m : evaluator.models()) after.push_back(m.hash);
  EXPECT_EQ(after, hashes);
  // Its score is the mean of its episodes on those models, in sample order.
  double sum = 0.0;
  for (const Robot& m : evaluator.models()) {
    sum += evaluate_team(m, config.period_s, config.complexity, config.duration_s, config.dt_s, team).score_m;
  }
  EXPECT_EQ(results[0].score_m, sum / 3.0);
  evaluator.set_generation(5);
  EXPECT_NE(evaluator.models()[0].hash, hashes[0]);
}

TEST(Randomized, OneZeroWidthSampleIsPlainEvolutionToTheBit) {
  const EvolveConfig plain = testing::short_physics_config(robot());
  EvolveConfig zero = plain;
  zero.randomization = ranges_text({{"motor_speed_scale", range(1, 1)},
                                    {"cable_stiffness_scale", range(1, 1)},
                                    {"cable_damping_scale", range(1, 1)},
                                    {"strut_mass_scale", range(1, 1)},
                                    {"friction_scale", range(1, 1)},
                                    {"slope_deg", range(0, 0)},
                                    {"rough_bump_height_m", range(0, 0)},
                                    {"load_cell_noise_n", range(0, 0)},
                                    {"load_cell_bias_n", range(0, 0)},
                                    {"actuation_delay_s", range(0, 0)}});
  zero.randomize_k = 1;
  auto threaded = make_episode_evaluator(robot(), plain, 2);
  auto sampled = make_episode_evaluator(robot(), zero, 2);
  ASSERT_NE(dynamic_cast<RandomizedEvaluator*>(sampled.get()), nullptr);
  EXPECT_EQ(run(plain, *threaded).curve, run(zero, *sampled).curve);
}

TEST(Randomized, TheCacheHoldsOnlyThisGenerationsSettledStarts) {
  // A seed of its own: models other tests drew (and left cached) are not drawn again.
  EvolveConfig config = randomized(testing::short_physics_config(robot()), 4);
  config.seed = 99;
  RandomizedEvaluator evaluator(robot(), config, 2);
  Team team;
  team.rest_lengths_m.assign(static_cast<std::size_t>(config.cables), std::vector<double>{0.8, 0.8, 0.8});
  const std::vector<Team> batch{team, team};
  evaluator.set_generation(1);
  (void)evaluator.evaluate(batch);
  const std::size_t held = settled_states_cached();
  for (int g = 2; g <= 4; ++g) {
    evaluator.set_generation(g);
    (void)evaluator.evaluate(batch);
    // The last generation's four left, this one's four came: never more.
    EXPECT_EQ(settled_states_cached(), held) << "generation " << g;
  }
}

TEST(Randomized, TheRandomizationIsPartOfTheConfigAndMpiRefusesIt) {
  const EvolveConfig config = randomized(testing::short_physics_config(robot()), 8);
  const EvolveConfig back = config_from_json(config_to_json(config));
  EXPECT_EQ(back.randomization, config.randomization);
  EXPECT_EQ(back.randomize_k, 8);
  EXPECT_TRUE(config_differences(config, back).empty());
  EXPECT_FALSE(config_differences(config, testing::short_physics_config(robot())).empty());
  EvolveConfig q25 = config;
  q25.randomize_score = SampleScore::q25;
  EXPECT_FALSE(config_differences(config, q25).empty());
  EXPECT_THROW(episode_team_function(robot(), config), ConfigError);
  EXPECT_THROW(episode_setup("{}", config), ConfigError);
  EvolveConfig bad = config;
  bad.randomize_k = 0;
  EXPECT_THROW(validate(bad), ConfigError);
}

}  // namespace
}  // namespace tensegrity::sim::evolve
