// SPDX-License-Identifier: Apache-2.0
#pragma once
// The Evaluator of an MPI run, on rank 0. The other ranks serve evaluations
// (mpi_worker.hpp): rank 0 sends each the setup once, then hands out teams one at a
// time from a work queue, to whichever rank (or own thread) is idle, so faster
// machines simply take more teams. Every result is placed by its team's index, and
// every rank scores with the same function of the team alone, so the results - and
// with them the whole run - are those of the threaded evaluator, bit for bit,
// whatever the number of ranks and threads.
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "sim/evolve/evaluator.hpp"
#include "sim/evolve/mpi_session.hpp"
#include "sim/evolve/mpi_wire.hpp"
#include "sim/evolve/team_workers.hpp"

namespace tensegrity::sim::evolve {

struct MpiEvaluatorOptions {
  // Rank 0's own evaluating threads; 0: rank 0 only hands out teams.
  int local_threads = 1;
  // A rank that holds a team and answers nothing for this long fails the run with
  // MpiFailure (a stopped or unreachable machine would otherwise hang it); <= 0:
  // wait forever. Also bounds the wait for each rank's answer to the setup.
  double timeout_s = 600.0;
};

struct RankLoad {
  int rank = 0;
  std::string host;
  int threads = 0;         // teams it evaluates at once
  std::int64_t teams = 0;  // teams it has evaluated so far
  std::string build;
};

class MpiEvaluator final : public Evaluator {
 public:
  // Sends `setup` to every other rank and waits for all their answers. `local` is
  // rank 0's scorer for the same setup. Throws MpiFailure (a rank is silent or MPI
  // failed) or std::runtime_error (the setup failed on a rank, or no rank would
  // evaluate anything).
  MpiEvaluator(MpiSession& session, const wire::Setup& setup, TeamFunction local, const MpiEvaluatorOptions& options);
  ~MpiEvaluator() override;

  // A team's evaluation that throws on any rank ends the batch (teams already handed
  // out are still awaited) with std::runtime_error naming the rank.
  std::vector<TeamResult> evaluate(std::span<const Team> teams) override;

  // Every rank, rank 0 first (its threads are the local ones).
  const std::vector<RankLoad>& ranks() const { return ranks_; }
  int threads() const;
  // E.g. ranks built with another compiler or C library, whose scores may differ
  // from rank 0's in the last bits.
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  struct Sent {
    std::uint64_t index = 0;
    std::chrono::steady_clock::time_point at;
  };
  void check_timeouts(const std::vector<std::vector<Sent>>& outstanding) const;

  MpiSession& session_;
  MpiEvaluatorOptions options_;
  std::unique_ptr<TeamWorkers> local_;
  std::vector<RankLoad> ranks_;
  std::vector<std::string> warnings_;
  std::uint64_t batch_ = 0;
};

}  // namespace tensegrity::sim::evolve
