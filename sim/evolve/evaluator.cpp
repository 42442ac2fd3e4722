// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/evaluator.hpp"

#include "sim/evolve/thread_pool.hpp"

namespace tensegrity::sim::evolve {

std::vector<TeamResult> FunctionEvaluator::evaluate(std::span<const Team> teams) {
  std::vector<TeamResult> results;
  results.reserve(teams.size());
  for (const Team& team : teams) results.push_back(function_(team));
  return results;
}

ParallelEvaluator::ParallelEvaluator(TeamFunction function, int threads)
    : function_(std::move(function)), pool_(std::make_unique<ThreadPool>(threads)) {}

ParallelEvaluator::~ParallelEvaluator() = default;

std::vector<TeamResult> ParallelEvaluator::evaluate(std::span<const Team> teams) {
  std::vector<TeamResult> results(teams.size());
  pool_->run(teams.size(), [&](std::size_t i) { results[i] = function_(teams[i]); });
  return results;
}

int ParallelEvaluator::threads() const { return pool_->threads(); }

}  // namespace tensegrity::sim::evolve
