// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/evolve_policy.hpp"

#include "sim/model/core_controller.hpp"
#include "sim/evolve/episode_evaluator.hpp"

namespace tensegrity::sim::evolve {

Policy best_policy(const Robot& robot, const EvolveConfig& config, const Coevolution& evo, double score_m) {
  Policy policy = team_policy(robot, config.period_s, config.complexity, evo.best().team);
  policy.provenance.method = to_string(config.method);
  policy.provenance.seed = config.seed;
  policy.provenance.episodes = evo.episodes();
  policy.provenance.score_m = score_m;
  policy.provenance.robot_hash = robot.hash;
  policy.provenance.population = config.population;
  policy.provenance.replace = config.replace;
  policy.provenance.teams = config.teams;
  policy.provenance.mutation = to_string(config.mutation);
  policy.provenance.sigma_m = config.sigma_m;
  policy.provenance.sigma_final_m = config.anneal_episodes > 0 ? config.sigma_final_m : config.sigma_m;
  policy.provenance.anneal_episodes = config.anneal_episodes;
  policy.provenance.anneal_start_episodes = config.anneal_episodes > 0 ? config.anneal_start_episodes : 0;
  return policy;
}

EpisodeResult play_gait(const Robot& robot, const EvolveConfig& config, Policy& policy) {
  CoreController controller(robot, policy);
  EpisodeOptions episode;
  episode.duration_s = config.duration_s;
  const EpisodeResult gait = run_episode(robot, controller, episode);
  policy.provenance.axial_spin_rms_rad_per_s = gait.axial_spin_rms_rad_per_s;
  policy.provenance.axial_spin_max_rad_per_s = gait.axial_spin_max_rad_per_s;
  policy.provenance.endcaps_touched_ground = gait.endcaps_touched_ground;
  policy.provenance.min_strut_gap_m = gait.min_strut_gap_m;
  policy.provenance.strut_overlap_s = gait.strut_overlap_s;
  policy.provenance.heading_deg = gait.travel.heading_deg;
  if (config.dt_s > 0.0) policy.provenance.score_m = gait.feasible ? gait.distance_m : 0.0;
  return gait;
}

}  // namespace tensegrity::sim::evolve
