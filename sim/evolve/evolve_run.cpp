// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/evolve_run.hpp"

#include <algorithm>
#include <chrono>
#include <vector>

#include "sim/evolve/episode_evaluator.hpp"
#include "sim/evolve/evolve_policy.hpp"
#include "sim/evolve/randomized_evaluator.hpp"

namespace tensegrity::sim::evolve {
namespace {

// The mutation step's schedule from the options (EvolveRequest says which defaults apply).
void set_step_schedule(EvolveConfig& config, const EvolveRequest& r) {
  const bool given =
      r.sigma_m >= 0.0 || r.sigma_final_m >= 0.0 || r.anneal_episodes >= 0 || r.anneal_start_episodes >= 0;
  if (!given && config.mutation == Mutation::gaussian) {
    const auto& s = kDefaultGaussianSchedule;
    config.sigma_m = s.sigma_m;
    config.sigma_final_m = s.sigma_final_m;
    config.anneal_start_episodes = s.anneal_start_episodes;
    config.anneal_episodes = s.anneal_episodes;
    return;
  }
  // Each operator's own step: 0.05 m for the Gaussian (a tenth of the 0.5 m range),
  // 0.03 of the range for the author's (NTRT's NeuroEvoMember::mutate).
  const double range_m = config.max_rest_length_m - config.min_rest_length_m;
  const double default_sigma_m =
      config.mutation == Mutation::author ? kAuthorSigmaShareOfRange * range_m : kDefaultGaussianSchedule.sigma_m;
  config.sigma_m = r.sigma_m < 0.0 ? default_sigma_m : r.sigma_m;
  config.sigma_final_m = r.sigma_final_m < 0.0 ? config.sigma_m : r.sigma_final_m;
  config.anneal_episodes = std::max<std::int64_t>(r.anneal_episodes, 0);
  config.anneal_start_episodes = std::max<std::int64_t>(r.anneal_start_episodes, 0);
}

// Robust learning's file and rule, checked against the robot.
void set_randomization(EvolveConfig& config, const EvolveRequest& r, const Robot& robot) {
  if (r.randomize.empty()) return;
  try {
    config.randomization = load_randomization(r.randomize).canonical;
  } catch (const RandomizationError& e) {
    throw ConfigError(std::string("--randomize: ") + e.what());
  }
  config.randomize_k = r.randomize_k;
  config.randomize_score = parse_sample_score(r.randomize_score);
  (void)config_randomization(config, robot);
}

}  // namespace

EvolveConfig request_config(const EvolveRequest& r, const Robot& robot) {
  EvolveConfig config;
  config.method = parse_fitness_method(r.method);
  config.population = r.population;
  config.teams = r.teams;
  config.replace = r.replace;
  config.mutation = parse_mutation(r.mutation);
  set_robot(config, robot);
  set_step_schedule(config, r);
  config.seed = r.seed;
  config.episodes = r.episodes;
  config.complexity = r.complexity;
  config.period_s = r.period_s;
  config.duration_s = r.duration_s;
  // The robot's own step asked for by name is the robot's own step: the same run, and
  // the same checkpoint, as one at a robot without a learning step of its own.
  config.dt_s = r.dt_s > 0.0 ? (r.dt_s == robot.time_step_s ? 0.0 : r.dt_s) : default_learning_dt_s(robot);
  set_default_early_end(config, robot);
  if (r.early_end_m >= 0.0) {
    if (r.early_end_m > 0.0 && config.early_end_speed_m_per_s <= 0.0) {
      throw ConfigError("--early-end: the robot has no learning.early_end.max_speed_m_per_s to bound progress by");
    }
    config.early_end_bar_m = r.early_end_m;
  }
  set_randomization(config, r, robot);
  validate(config);
  return config;
}

EvolveOutcome run_evolution(const Robot& robot, const EvolveConfig& config, Evaluator& evaluator, const RunFiles& files,
                            const std::function<void(const Coevolution&, const GenerationStats&)>& on_generation) {
  // Hours of evolution must not end in "cannot write": make the policy's directory now.
  if (files.policy.has_parent_path()) std::filesystem::create_directories(files.policy.parent_path());
  DriverOptions options;
  options.checkpoint_dir = files.checkpoint_dir;
  options.resume = files.resume;
  options.curve_csv = files.curve_csv;
  options.on_generation = on_generation;
  const auto started = std::chrono::steady_clock::now();
  EvolveOutcome o{drive(config, evaluator, options), TeamResult{}, EpisodeResult{}, Policy{}, 0.0};
  const std::vector<Team> final_team{o.result.evolution.best().team};
  evaluator.set_generation(o.result.evolution.generation() + 1);
  o.final_result = evaluator.evaluate(final_team).front();
  o.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  o.policy = best_policy(robot, config, o.result.evolution, o.final_result.score_m);
  o.gait = play_gait(robot, config, o.policy);
  save_policy(files.policy, o.policy);
  return o;
}

}  // namespace tensegrity::sim::evolve
