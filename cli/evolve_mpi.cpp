// SPDX-License-Identifier: Apache-2.0
#include "cli/evolve_mpi.hpp"

#include <cstdio>
#include <memory>

#include "cli/commands.hpp"
#include "sim/evolve/mpi_launch.hpp"

#if TENSEGRITY_WITH_MPI
#include "sim/evolve/episode_evaluator.hpp"
#include "sim/evolve/episode_setup.hpp"
#include "sim/evolve/mpi_evaluator.hpp"
#include "sim/evolve/mpi_session.hpp"
#include "sim/evolve/mpi_worker.hpp"
#endif

namespace tensegrity::cli {

void check_evolve_launch(bool mpi) {
  const auto launched = sim::evolve::mpi_launch_size();
  if (!mpi) {
    if (launched && *launched > 1) {
      throw CommandError(ExitCode::usage,
                         "started by mpirun as " + std::to_string(*launched) +
                             " processes without --mpi: each would run the whole evolution and write the "
                             "same files; add --mpi");
    }
    return;
  }
  if (!sim::evolve::mpi_built()) {
    throw CommandError(ExitCode::usage,
                       "--mpi: this tensegrity was built without MPI (install libopenmpi-dev and configure "
                       "with -DTENSEGRITY_WITH_MPI=ON)");
  }
  if (!launched) {
    throw CommandError(ExitCode::usage,
                       "--mpi: not started by mpirun; run e.g. `mpirun -np 4 tensegrity evolve ... --mpi` "
                       "(docs/guide/evolve.md)");
  }
}

#if TENSEGRITY_WITH_MPI
namespace {

namespace ev = sim::evolve;

class Coordinator final : public EvolveMpi {
 public:
  Coordinator(ev::MpiSession& session, const EvolveMpiArgs& args, int threads)
      : session_(session), args_(args), threads_(threads) {}

  ev::Evaluator& evaluator(const std::string& robot_json, const sim::Robot& robot,
                           const ev::EvolveConfig& config) override {
    ev::MpiEvaluatorOptions options;
    options.local_threads = args_.root_threads >= 0 ? args_.root_threads : threads_;
    options.timeout_s = args_.timeout_s;
    try {
      evaluator_ = std::make_unique<ev::MpiEvaluator>(session_, ev::to_wire(ev::episode_setup(robot_json, config)),
                                                      ev::episode_team_function(robot, config), options);
    } catch (const ev::MpiFailure&) {
      throw;
    } catch (const std::exception& e) {
      throw CommandError(ExitCode::usage, e.what());
    }
    for (const auto& w : evaluator_->warnings()) std::fprintf(stderr, "tensegrity: warning: %s\n", w.c_str());
    return *evaluator_;
  }
  int ranks() const override { return session_.size(); }
  int threads() const override { return evaluator_ ? evaluator_->threads() : 0; }
  nlohmann::json loads() const override {
    nlohmann::json out = nlohmann::json::array();
    if (!evaluator_) return out;
    for (const auto& r : evaluator_->ranks()) {
      out.push_back({{"rank", r.rank}, {"host", r.host}, {"threads", r.threads}, {"teams", r.teams}});
    }
    return out;
  }

 private:
  ev::MpiSession& session_;
  EvolveMpiArgs args_;
  int threads_;
  std::unique_ptr<ev::MpiEvaluator> evaluator_;
};

// The resumable state lives on rank 0 only; say so, since an aborted job ends every
// rank with messages from mpirun that do not.
[[noreturn]] void abort_job(ev::MpiSession& session, const std::exception& e) {
  std::fprintf(stderr,
               "tensegrity: rank %d: %s\n"
               "tensegrity: aborting the MPI job; the checkpoint (if any) holds the last whole generation: rerun "
               "with --resume\n",
               session.rank(), e.what());
  session.abort(ExitCode::mpi);
}

}  // namespace

void run_evolve_mpi(const EvolveMpiArgs& args, const std::function<void(EvolveMpi&)>& coordinate) {
  std::unique_ptr<ev::MpiSession> session;
  try {
    session = std::make_unique<ev::MpiSession>();
  } catch (const ev::MpiFailure& e) {
    throw CommandError(ExitCode::mpi, std::string("--mpi: ") + e.what());
  }
  const int cpus = ev::usable_cpus();
  const int threads = args.threads > 0 ? args.threads : cpus;
  const bool evaluates = session->rank() != 0 || args.root_threads != 0;
  const int own = session->rank() == 0 && args.root_threads >= 0 ? args.root_threads : threads;
  if (evaluates && own > cpus) {
    // mpirun binds each rank to one core when it starts two or fewer: threads
    // beyond that would take turns on it.
    std::fprintf(stderr,
                 "tensegrity: warning: rank %d runs %d evaluation threads on %d usable CPU(s) (%s); "
                 "with mpirun, pass --bind-to none for ranks with several threads\n",
                 session->rank(), own, cpus, session->host().c_str());
  }
  if (session->rank() != 0) {
    try {
      ev::serve_evaluations(*session, threads, [](const ev::wire::Setup& setup) {
        return ev::episode_team_function(ev::episode_setup_from_wire(setup));
      });
    } catch (const std::exception& e) {
      abort_job(*session, e);
    }
    return;
  }
  Coordinator coordinator(*session, args, threads);
  try {
    coordinate(coordinator);
  } catch (const ev::MpiFailure& e) {
    abort_job(*session, e);
  }
  // Leaving destroys the session: the other ranks are told to stop, then MPI ends;
  // an error on its way up takes the same path, so they stop rather than hang.
}

#else

void run_evolve_mpi(const EvolveMpiArgs&, const std::function<void(EvolveMpi&)>&) {
  throw CommandError(ExitCode::usage, "--mpi: this tensegrity was built without MPI");
}

#endif

}  // namespace tensegrity::cli
