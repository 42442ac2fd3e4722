// SPDX-License-Identifier: Apache-2.0
#pragma once
// The coevolution asks for scores of a batch of teams and nothing else: how they are
// scored (physics on a thread pool, a synthetic function in tests, later MPI ranks)
// is an Evaluator. A batch is plain numbers in and plain numbers out, so it can be
// shipped to other processes unchanged.
#include <cstddef>
#include <functional>
#include <memory>
#include <span>
#include <vector>

namespace tensegrity::sim::evolve {

class ThreadPool;

// One member of every population: rest_lengths_m[cable][j], j < complexity.
struct Team {
  std::vector<std::vector<double>> rest_lengths_m;
};

struct TeamResult {
  double score_m = 0.0;  // the coevolution scores an infeasible team 0 whatever this says
  bool feasible = true;
};

class Evaluator {
 public:
  virtual ~Evaluator() = default;
  // results[i] belongs to teams[i]. Must depend on teams[i] alone (not on the batch,
  // the order or the thread), or runs stop being reproducible.
  virtual std::vector<TeamResult> evaluate(std::span<const Team> teams) = 0;
  // The generation (1 for the first) whose teams the next batches are. An evaluator
  // whose models change every generation (randomized models) draws them for it; every
  // team of a generation then meets the same models. The others ignore it.
  virtual void set_generation(int /*generation*/) {}
};

using TeamFunction = std::function<TeamResult(const Team&)>;

// Calls a function for each team, in order, on the calling thread.
class FunctionEvaluator final : public Evaluator {
 public:
  explicit FunctionEvaluator(TeamFunction function) : function_(std::move(function)) {}
  std::vector<TeamResult> evaluate(std::span<const Team> teams) override;

 private:
  TeamFunction function_;
};

// Calls a thread-safe function for each team on `threads` workers; results are
// placed by team index, so they do not depend on the thread count or scheduling.
class ParallelEvaluator final : public Evaluator {
 public:
  ParallelEvaluator(TeamFunction function, int threads);
  ~ParallelEvaluator() override;
  std::vector<TeamResult> evaluate(std::span<const Team> teams) override;
  int threads() const;

 private:
  TeamFunction function_;
  std::unique_ptr<ThreadPool> pool_;
};

}  // namespace tensegrity::sim::evolve
