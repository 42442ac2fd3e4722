// SPDX-License-Identifier: Apache-2.0
// The two mutation operators on a fixed seed: the author's (NTRT NeuroEvoMember::mutate:
// half the copies untouched, half the values of the others, N(0, (0.03 range)^2),
// clamped) and the Gaussian one (every value of every copy). Shares are checked
// against their exact expectations within four binomial standard deviations.
#include <gtest/gtest.h>

#include <cmath>
#include <span>
#include <nlohmann/json.hpp>

#include "sim/evolve/coevolution.hpp"
#include "tests/sim/evolve/synthetic.hpp"

namespace tensegrity::sim::evolve {
namespace {

constexpr int kCopies = 20000;
constexpr int kValues = 5;

EvolveConfig author_config(Mutation mutation = Mutation::author) {
  EvolveConfig c = testing::synthetic_config(FitnessMethod::historical, 1000, 11);
  c.complexity = kValues;
  c.mutation = mutation;
  c.sigma_m = kAuthorSigmaShareOfRange * (c.max_rest_length_m - c.min_rest_length_m);
  c.sigma_final_m = c.sigma_m;
  return c;
}

struct Tally {
  int untouched_copies = 0;
  int changed_values = 0;
  double sum_sq_step = 0.0;
};

Tally mutate_many(Coevolution& evo, double start_m) {
  Tally t;
  for (int i = 0; i < kCopies; ++i) {
    std::vector<double> values(kValues, start_m);
    evo.mutate(values, evo.config().sigma_m);
    int changed = 0;
    for (double v : values) {
      if (v == start_m) continue;
      ++changed;
      t.sum_sq_step += (v - start_m) * (v - start_m);
    }
    t.changed_values += changed;
    if (changed == 0) ++t.untouched_copies;
  }
  return t;
}

double tolerance(double p, int n) { return 4.0 * std::sqrt(p * (1.0 - p) / n); }

TEST(Mutation, AuthorLeavesHalfTheCopiesAndHalfTheValuesOfTheRest) {
  Coevolution evo(author_config());
  const Tally t = mutate_many(evo, 0.85);
  // A copy is unchanged when it is skipped (1/2) or when all its values are (1/2 * 1/2^5).
  const double p_untouched = 0.5 + 0.5 * std::pow(0.5, kValues);
  EXPECT_NEAR(static_cast<double>(t.untouched_copies) / kCopies, p_untouched, tolerance(p_untouched, kCopies));
  const int values = kCopies * kValues;
  EXPECT_NEAR(static_cast<double>(t.changed_values) / values, 0.25, tolerance(0.25, values));
}

TEST(Mutation, AuthorStepIsThreePercentOfTheRange) {
  Coevolution evo(author_config());
  EXPECT_DOUBLE_EQ(evo.config().sigma_m, 0.015);  // 0.03 of 0.6-1.1 m
  const Tally t = mutate_many(evo, 0.85);         // 0.25 m from a limit: 16 sigma, no clamping
  const double sigma = std::sqrt(t.sum_sq_step / t.changed_values);
  // The sample sd of ~25,000 normals is within 2 % of sigma with overwhelming probability.
  EXPECT_NEAR(sigma, 0.015, 0.02 * 0.015);
}

TEST(Mutation, AuthorClampsToTheLimits) {
  EvolveConfig c = author_config();
  Coevolution evo(c);
  const Tally t = mutate_many(evo, c.max_rest_length_m);
  // Every upward step is clamped back onto the limit, so is indistinguishable from no
  // step: changed values are the downward half of the mutated ones.
  const int values = kCopies * kValues;
  EXPECT_NEAR(static_cast<double>(t.changed_values) / values, 0.125, tolerance(0.125, values));
  std::vector<double> values_at_limit(kValues, c.max_rest_length_m);
  for (int i = 0; i < 1000; ++i) {
    evo.mutate(values_at_limit, 0.3);  // large steps: both limits are hit
    for (double v : values_at_limit) {
      ASSERT_GE(v, c.min_rest_length_m);
      ASSERT_LE(v, c.max_rest_length_m);
    }
  }
}

TEST(Mutation, GaussianMovesEveryValueOfEveryCopy) {
  Coevolution evo(author_config(Mutation::gaussian));
  const Tally t = mutate_many(evo, 0.85);
  EXPECT_EQ(t.untouched_copies, 0);
  EXPECT_EQ(t.changed_values, kCopies * kValues);
}

TEST(Mutation, TheOperatorIsPartOfTheConfigAndOldConfigsAreGaussian) {
  const EvolveConfig c = author_config();
  nlohmann::json j = config_to_json(c);
  EXPECT_EQ(j.at("mutation"), "author");
  EXPECT_EQ(config_from_json(j).mutation, Mutation::author);
  EXPECT_EQ(config_differences(c, author_config(Mutation::gaussian)).size(), 1u);
  j.erase("mutation");
  EXPECT_EQ(config_from_json(j).mutation, Mutation::gaussian);
  j["mutation"] = "uniform";
  EXPECT_THROW((void)config_from_json(j), ConfigError);
  EXPECT_THROW((void)parse_mutation("Author"), ConfigError);
}

TEST(Mutation, AuthorRunsFindTheSyntheticOptimumToo) {
  EvolveConfig c = author_config();
  c.complexity = 2;
  c.sigma_m = c.sigma_final_m = 0.01;
  c.episodes = 20000;
  Coevolution evo(c);
  struct Synthetic : Evaluator {
    std::vector<TeamResult> evaluate(std::span<const Team> teams) override {
      std::vector<TeamResult> out;
      for (const auto& team : teams) out.push_back(testing::synthetic_score(team));
      return out;
    }
  } evaluator;
  while (!evo.done()) (void)evo.step(evaluator);
  EXPECT_GT(evo.best().score_m, 9.9);
}

}  // namespace
}  // namespace tensegrity::sim::evolve
