// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/coevolution.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace tensegrity::sim::evolve {

double fitness(FitnessMethod method, const std::vector<double>& history) {
  if (history.empty()) return -std::numeric_limits<double>::infinity();
  if (method == FitnessMethod::leniency) return *std::max_element(history.begin(), history.end());
  // historical and average differ in how long the history is kept, not in this.
  return std::accumulate(history.begin(), history.end(), 0.0) / static_cast<double>(history.size());
}

namespace {

void check_state(const EvolveConfig& c, const CoevolutionState& s) {
  auto fail = [](const std::string& what) { throw ConfigError("coevolution state: " + what); };
  if (s.generation < 0 || s.episodes < 0 || s.infeasible_episodes < 0 || s.infeasible_episodes > s.episodes) {
    fail("negative or inconsistent counters");
  }
  if (static_cast<int>(s.curve.size()) != s.generation) fail("curve length differs from the generation count");
  if (static_cast<int>(s.populations.size()) != c.cables) fail("one population per cable expected");
  for (const auto& population : s.populations) {
    if (static_cast<int>(population.size()) != c.population) fail("population size differs from the config");
    for (const auto& member : population) {
      if (static_cast<int>(member.rest_lengths_m.size()) != c.complexity) fail("member length differs from complexity");
      for (double v : member.rest_lengths_m) {
        if (!(v >= c.min_rest_length_m && v <= c.max_rest_length_m))
          fail("member value outside the rest-length limits");
      }
      for (double h : member.history) {
        if (!std::isfinite(h)) fail("non-finite score in a history");
      }
    }
  }
  if (s.best.found) {
    if (static_cast<int>(s.best.team.rest_lengths_m.size()) != c.cables) fail("best team has the wrong cable count");
    for (const auto& values : s.best.team.rest_lengths_m) {
      if (static_cast<int>(values.size()) != c.complexity) fail("best team has the wrong complexity");
    }
  }
}

}  // namespace

Coevolution::Coevolution(const EvolveConfig& config) : config_(config), rng_(config.seed) {
  validate(config_);
  state_.populations.resize(static_cast<std::size_t>(config_.cables));
  for (auto& population : state_.populations) {
    population.resize(static_cast<std::size_t>(config_.population));
    for (auto& member : population) {
      member.rest_lengths_m.resize(static_cast<std::size_t>(config_.complexity));
      for (double& v : member.rest_lengths_m) v = rng_.uniform(config_.min_rest_length_m, config_.max_rest_length_m);
    }
  }
}

Coevolution::Coevolution(const EvolveConfig& config, CoevolutionState state)
    : config_(config), rng_(config.seed), state_(std::move(state)) {
  validate(config_);
  check_state(config_, state_);
  try {
    rng_.set_state(state_.rng_state);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(std::string("coevolution state: rng: ") + e.what());
  }
  state_.rng_state.clear();
}

CoevolutionState Coevolution::state() const {
  CoevolutionState copy = state_;
  copy.rng_state = rng_.state();
  return copy;
}

Team Coevolution::team(const TeamPicks& picks) const {
  Team t;
  t.rest_lengths_m.reserve(picks.size());
  for (std::size_t c = 0; c < picks.size(); ++c) {
    t.rest_lengths_m.push_back(state_.populations[c][static_cast<std::size_t>(picks[c])].rest_lengths_m);
  }
  return t;
}

std::vector<TeamPicks> Coevolution::sample_teams(int count) {
  std::vector<TeamPicks> picks(static_cast<std::size_t>(count));
  for (auto& p : picks) {
    p.resize(static_cast<std::size_t>(config_.cables));
    for (int& index : p) index = static_cast<int>(rng_.below(static_cast<std::size_t>(config_.population)));
  }
  return picks;
}

GenerationStats Coevolution::record(const std::vector<TeamPicks>& picks, const std::vector<Team>& teams,
                                    const std::vector<TeamResult>& results) {
  if (results.size() != picks.size() || teams.size() != picks.size()) {
    throw std::runtime_error("evaluator returned " + std::to_string(results.size()) + " results for " +
                             std::to_string(picks.size()) + " teams");
  }
  GenerationStats stats;
  stats.generation = state_.generation + 1;
  stats.teams = static_cast<int>(picks.size());
  stats.best_score_m = -std::numeric_limits<double>::infinity();
  double sum = 0.0;
  for (std::size_t t = 0; t < picks.size(); ++t) {
    // A policy the robot cannot survive is worth nothing, however far it got first;
    // a non-finite score is a broken evaluation and counts the same.
    const bool feasible = results[t].feasible && std::isfinite(results[t].score_m);
    const double score = feasible ? results[t].score_m : 0.0;
    ++state_.episodes;
    if (!feasible) {
      ++stats.infeasible;
      ++state_.infeasible_episodes;
    }
    sum += score;
    stats.best_score_m = std::max(stats.best_score_m, score);
    for (std::size_t c = 0; c < picks[t].size(); ++c) {
      state_.populations[c][static_cast<std::size_t>(picks[t][c])].history.push_back(score);
    }
    // A feasible team beats an infeasible one; among equals the first seen stays.
    BestTeam& best = state_.best;
    if (!best.found || (feasible && !best.feasible) || (feasible == best.feasible && score > best.score_m)) {
      best = BestTeam{true, teams[t], score, feasible, state_.episodes, stats.generation};
    }
  }
  stats.episodes = state_.episodes;
  stats.mean_score_m = picks.empty() ? 0.0 : sum / static_cast<double>(picks.size());
  if (picks.empty()) stats.best_score_m = 0.0;
  stats.best_so_far_m = state_.best.score_m;
  return stats;
}

void Coevolution::mutate(std::vector<double>& values, double sigma_m) {
  const bool author = config_.mutation == Mutation::author;
  // The draw order (copy, then per value: keep?, step) is part of a run's identity.
  if (author && rng_.uniform01() < kAuthorCopyUntouchedProbability) return;
  for (double& v : values) {
    if (author && rng_.uniform01() < kAuthorValueUntouchedProbability) continue;
    v = std::clamp(v + sigma_m * rng_.normal(), config_.min_rest_length_m, config_.max_rest_length_m);
  }
}

void Coevolution::select_and_breed() {
  const auto n = static_cast<std::size_t>(config_.population);
  const auto z = static_cast<std::size_t>(config_.replace);
  const double sigma_m = mutation_sigma_m(config_, state_.episodes);
  for (auto& population : state_.populations) {
    std::vector<double> f(n);
    for (std::size_t i = 0; i < n; ++i) f[i] = fitness(config_.method, population[i].history);
    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), std::size_t{0});
    // Stable: equal fitness keeps the current order, so ranking is deterministic.
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return f[a] > f[b]; });
    std::vector<Member> ranked;
    ranked.reserve(n);
    for (std::size_t i : order) ranked.push_back(std::move(population[i]));
    for (std::size_t i = 0; i < z; ++i) {
      Member& copy = ranked[n - z + i];
      copy.rest_lengths_m = ranked[i].rest_lengths_m;
      copy.history.clear();
      mutate(copy.rest_lengths_m, sigma_m);
    }
    if (config_.method != FitnessMethod::historical) {
      for (auto& member : ranked) member.history.clear();
    }
    population = std::move(ranked);
  }
}

const GenerationStats& Coevolution::step(Evaluator& evaluator) {
  if (done()) throw std::logic_error("coevolution: episode budget already spent");
  const auto count = static_cast<int>(std::min<std::int64_t>(config_.teams, config_.episodes - state_.episodes));
  const std::vector<TeamPicks> picks = sample_teams(count);
  std::vector<Team> teams;
  teams.reserve(picks.size());
  for (const auto& p : picks) teams.push_back(team(p));
  evaluator.set_generation(state_.generation + 1);
  const std::vector<TeamResult> results = evaluator.evaluate(teams);
  GenerationStats stats = record(picks, teams, results);
  select_and_breed();
  ++state_.generation;
  state_.curve.push_back(stats);
  return state_.curve.back();
}

}  // namespace tensegrity::sim::evolve
