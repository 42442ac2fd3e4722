// SPDX-License-Identifier: Apache-2.0
#pragma once
// Cooperative coevolution, Algorithm 1 of the paper: one population per cable
// controller; every generation random teams (one member from every population) are
// scored, each score is appended to the history of every member of its team, the
// members are ranked by fitness, the best `replace` are copied over the worst, the
// copies are mutated and their history cleared. All randomness comes from one seeded
// engine on the calling thread, so a run depends on its config and nothing else.
#include <cstdint>
#include <string>
#include <vector>

#include "sim/evolve/config.hpp"
#include "sim/evolve/evaluator.hpp"
#include "sim/evolve/rng.hpp"

namespace tensegrity::sim::evolve {

struct Member {
  std::vector<double> rest_lengths_m;  // `complexity` values
  std::vector<double> history;         // team scores since the member was made
};

struct GenerationStats {
  int generation = 0;          // 1 for the first generation
  std::int64_t episodes = 0;   // total so far, this generation included
  int teams = 0;               // evaluated this generation
  int infeasible = 0;          // of those, infeasible (scored 0)
  double best_score_m = 0.0;   // best team this generation
  double mean_score_m = 0.0;   // mean team score this generation
  double best_so_far_m = 0.0;  // best team of the run so far
  double infeasible_rate() const { return teams > 0 ? static_cast<double>(infeasible) / teams : 0.0; }
};

struct BestTeam {
  bool found = false;
  Team team;
  double score_m = 0.0;
  bool feasible = false;
  std::int64_t episode = 0;  // 1-based index of the evaluation that scored it
  int generation = 0;
};

// Everything a run needs to continue: what a checkpoint holds.
struct CoevolutionState {
  int generation = 0;  // generations completed
  std::int64_t episodes = 0;
  std::int64_t infeasible_episodes = 0;
  std::string rng_state;
  std::vector<std::vector<Member>> populations;  // [cable][member], best first after a generation
  std::vector<GenerationStats> curve;
  BestTeam best;
};

// The members chosen for one team: picks[cable] indexes populations[cable].
using TeamPicks = std::vector<int>;

// The fitness a method gives a history; -infinity for a member not scored yet, which
// therefore ranks below every scored one (an unscored copy is replaced first).
double fitness(FitnessMethod method, const std::vector<double>& history);

class Coevolution {
 public:
  // A fresh run: every value uniform in the rest-length limits.
  explicit Coevolution(const EvolveConfig& config);
  // Continues from a saved state (checked for shape and limits; throws ConfigError).
  Coevolution(const EvolveConfig& config, CoevolutionState state);

  bool done() const { return state_.episodes >= config_.episodes; }
  // One generation: min(teams, budget left) teams scored by `evaluator`.
  const GenerationStats& step(Evaluator& evaluator);

  const EvolveConfig& config() const { return config_; }
  // A copy of the whole state, the engine's included (what a checkpoint saves).
  CoevolutionState state() const;
  const std::vector<std::vector<Member>>& populations() const { return state_.populations; }
  const std::vector<GenerationStats>& curve() const { return state_.curve; }
  const BestTeam& best() const { return state_.best; }
  int generation() const { return state_.generation; }
  std::int64_t episodes() const { return state_.episodes; }
  Team team(const TeamPicks& picks) const;

  // The phases of step(), public so that tests can check each one.
  std::vector<TeamPicks> sample_teams(int count);
  GenerationStats record(const std::vector<TeamPicks>& picks, const std::vector<Team>& teams,
                         const std::vector<TeamResult>& results);
  void select_and_breed();
  // A copy's values mutated in place by the config's operator at step `sigma_m`.
  void mutate(std::vector<double>& values, double sigma_m);

 private:
  EvolveConfig config_;
  Rng rng_;
  CoevolutionState state_;  // rng_state is filled in by state() only
};

}  // namespace tensegrity::sim::evolve
