// SPDX-License-Identifier: Apache-2.0
#pragma once
// `tensegrity evolve --mpi`: the launch checks, MPI's start and end, and the split
// of roles: rank 0 runs the coevolution exactly as without MPI (checkpoints, curve,
// policy), every other rank only serves evaluations. Compiled in every build; in
// one without MPI asking for it is a clear error.
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "sim/evolve/config.hpp"
#include "sim/evolve/evaluator.hpp"
#include "robot/robot.hpp"

namespace tensegrity::cli {

struct EvolveMpiArgs {
  int threads = 0;        // per rank; 0: the CPUs the rank may run on
  int root_threads = -1;  // rank 0's evaluating threads; < 0: as `threads`
  double timeout_s = 600.0;
};

// Rank 0's side of the MPI run.
class EvolveMpi {
 public:
  virtual ~EvolveMpi() = default;
  // Sends the setup to every rank and returns the evaluator that spreads teams over
  // them (rank 0's own threads included). Once per run.
  virtual sim::evolve::Evaluator& evaluator(const std::string& robot_json, const sim::Robot& robot,
                                            const sim::evolve::EvolveConfig& config) = 0;
  virtual int ranks() const = 0;
  virtual int threads() const = 0;  // over all ranks
  // Per rank: host, threads, teams evaluated.
  virtual nlohmann::json loads() const = 0;
};

// Throws CommandError(ExitCode::usage) for a launch that cannot work: --mpi in a build without
// MPI or outside mpirun, or mpirun with several processes but no --mpi (each would
// run the whole evolution and write the same files).
void check_evolve_launch(bool mpi);

// Starts MPI; rank 0 runs `coordinate`, the others serve until it is done. An MPI
// failure (a rank died, hung or broke the protocol) is printed and aborts the whole
// job; other errors on rank 0 stop the other ranks and propagate.
void run_evolve_mpi(const EvolveMpiArgs& args, const std::function<void(EvolveMpi&)>& coordinate);

}  // namespace tensegrity::cli
