// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/randomized_evaluator.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "sim/analysis/faulty_controller.hpp"
#include "sim/evolve/episode_evaluator.hpp"
#include "sim/evolve/thread_pool.hpp"
#include "sim/model/core_controller.hpp"
#include "sim/model/settled_cache.hpp"

namespace tensegrity::sim::evolve {

Randomization config_randomization(const EvolveConfig& config, const Robot& robot) {
  Randomization r;
  try {
    r = parse_randomization(config.randomization, "randomization of the run");
  } catch (const RandomizationError& e) {
    throw ConfigError(e.what());
  }
  if (robot.engine == Robot::PhysicsEngine::bullet && r.rough_bump_height_m.given && r.rough_bump_height_m.max > 0.0) {
    throw ConfigError("randomization: ranges.rough_bump_height_m: the bullet engine has no rough ground");
  }
  return r;
}

double combine_sample_scores(SampleScore rule, std::vector<double> scores_m) {
  if (scores_m.empty()) return 0.0;
  if (rule == SampleScore::mean) {
    double sum = 0.0;
    for (double s : scores_m) sum += s;
    return sum / static_cast<double>(scores_m.size());
  }
  std::sort(scores_m.begin(), scores_m.end());
  const double position = 0.25 * static_cast<double>(scores_m.size() - 1);
  const auto below = static_cast<std::size_t>(std::floor(position));
  const std::size_t above = std::min(below + 1, scores_m.size() - 1);
  const double t = position - static_cast<double>(below);
  return scores_m[below] + t * (scores_m[above] - scores_m[below]);
}

RandomizedEvaluator::RandomizedEvaluator(const Robot& robot, const EvolveConfig& config, int threads)
    : robot_(robot),
      config_(config),
      ranges_(config_randomization(config, robot)),
      pool_(std::make_unique<ThreadPool>(threads)) {
  validate(config_);
  if (robot.cable_count() != config.cables) {
    throw ConfigError("robot has " + std::to_string(robot.cable_count()) + " cables, config " +
                      std::to_string(config.cables));
  }
  set_generation(1);
}

RandomizedEvaluator::~RandomizedEvaluator() = default;

void RandomizedEvaluator::set_generation(int generation) {
  if (generation == generation_ && !models_.empty()) return;
  std::vector<Sample> samples;
  std::vector<Robot> models;
  std::set<std::string> hashes;
  for (int k = 0; k < config_.randomize_k; ++k) {
    samples.push_back(draw_sample(ranges_, config_.seed, generation, k));
    try {
      models.push_back(sampled_robot(robot_, samples.back()));
    } catch (const RandomizationError& e) {
      throw ConfigError(std::string("randomization: ") + e.what());
    }
    hashes.insert(models.back().hash);
  }
  // The cache keeps a settled start per model: only this generation's are kept (a
  // model drawn again, as with zero-width ranges, keeps its start).
  for (const Robot& old : models_) {
    if (!hashes.contains(old.hash)) forget_settled_state(old, config_.dt_s);
  }
  samples_ = std::move(samples);
  models_ = std::move(models);
  generation_ = generation;
}

namespace {

TeamResult score_on(const Robot& model, const Sample& sample, const EvolveConfig& config, const Team& team) {
  const Policy policy = team_policy(model, config.period_s, config.complexity, team);
  CoreController core(model, policy);
  const PerturbationCase& c = sample.change;
  FaultyController controller(
      core, HardwareFaults{c.load_cell_noise_n, c.load_cell_bias_n, c.load_cell_seed, c.actuation_delay_s});
  return score_episode(model, controller, config.duration_s, config.dt_s,
                       EarlyEnd{config.early_end_bar_m, config.early_end_speed_m_per_s});
}

}  // namespace

std::vector<TeamResult> RandomizedEvaluator::evaluate(std::span<const Team> teams) {
  const std::size_t k = models_.size();
  std::vector<TeamResult> per_sample(teams.size() * k);
  // One job per (team, sample): results are placed by index, so they do not depend
  // on the thread count.
  pool_->run(per_sample.size(),
             [&](std::size_t i) { per_sample[i] = score_on(models_[i % k], samples_[i % k], config_, teams[i / k]); });
  std::vector<TeamResult> results(teams.size());
  for (std::size_t t = 0; t < teams.size(); ++t) {
    std::vector<double> scores(k);
    bool feasible = true;
    for (std::size_t s = 0; s < k; ++s) {
      const TeamResult& r = per_sample[t * k + s];
      feasible = feasible && r.feasible;
      scores[s] = r.score_m;
    }
    results[t] =
        feasible ? TeamResult{combine_sample_scores(config_.randomize_score, scores), true} : TeamResult{0.0, false};
  }
  return results;
}

}  // namespace tensegrity::sim::evolve
