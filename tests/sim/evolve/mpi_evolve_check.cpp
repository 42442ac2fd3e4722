// SPDX-License-Identifier: Apache-2.0
// Run under mpirun (ctest: `mpirun -np 3`): the MPI evaluator gives the run the
// in-process evaluators give, bit for bit, whether rank 0 evaluates or only hands
// out teams, with ranks of different thread counts; evaluation errors and failed
// setups come back to rank 0 as errors naming the rank, and the job goes on.
// Rank 0 prints one line per check and exits non-zero if any failed; the other
// ranks serve (rank r with r threads, so the ranks differ).
#include <cstdio>
#include <stdexcept>
#include <string>

#include "sim/evolve/checkpoint.hpp"
#include "sim/evolve/curve_csv.hpp"
#include "sim/evolve/driver.hpp"
#include "sim/evolve/episode_evaluator.hpp"
#include "sim/evolve/episode_setup.hpp"
#include "sim/evolve/mpi_evaluator.hpp"
#include "sim/evolve/mpi_session.hpp"
#include "sim/evolve/mpi_worker.hpp"
#include "robot/robot.hpp"
#include "tests/sim/evolve/synthetic.hpp"

#include "tests/sim/evolve/run_outcome.hpp"

namespace tensegrity::sim::evolve {
namespace {

constexpr const char* kSynthetic = "test-synthetic";
constexpr const char* kThrowing = "test-throwing";

TeamResult throwing_score(const Team& team) {
  if (team.rest_lengths_m[0][0] > 0.8) throw std::runtime_error("synthetic failure");
  return testing::synthetic_score(team);
}

TeamFunction factory(const wire::Setup& setup) {
  if (setup.kind == kSynthetic) return testing::synthetic_score;
  if (setup.kind == kThrowing) return throwing_score;
  return episode_team_function(episode_setup_from_wire(setup));
}

using Outcome = testing::RunOutcome;

Outcome run(const EvolveConfig& config, Evaluator& evaluator) { return testing::run_outcome(config, evaluator); }

int failures = 0;

void check(bool ok, const std::string& what) {
  std::printf("%s %s\n", ok ? "ok  " : "FAIL", what.c_str());
  std::fflush(stdout);
  if (!ok) ++failures;
}

std::string loads(const MpiEvaluator& e) {
  std::string text;
  for (const auto& r : e.ranks()) {
    text += " r" + std::to_string(r.rank) + ":" + std::to_string(r.threads) + "t/" + std::to_string(r.teams);
  }
  return text;
}

void synthetic_runs(MpiSession& session) {
  const EvolveConfig config = testing::synthetic_config(FitnessMethod::historical, 600, 11);
  FunctionEvaluator reference_evaluator(testing::synthetic_score);
  const Outcome reference = run(config, reference_evaluator);
  for (int local : {0, 1, 2}) {
    MpiEvaluator evaluator(session, wire::Setup{wire::kProtocol, kSynthetic, {}}, testing::synthetic_score,
                           MpiEvaluatorOptions{local, 60.0});
    const Outcome got = run(config, evaluator);
    check(got.curve == reference.curve && got.state == reference.state,
          "synthetic run, rank 0 with " + std::to_string(local) + " threads, equals the in-process run;" +
              loads(evaluator));
    std::int64_t remote = 0;
    for (const auto& r : evaluator.ranks()) remote += r.rank == 0 ? 0 : r.teams;
    check(session.size() == 1 || remote > 0, "the other ranks evaluated teams");
  }
}

void errors(MpiSession& session) {
  {
    MpiEvaluator evaluator(session, wire::Setup{wire::kProtocol, kThrowing, {}}, throwing_score,
                           MpiEvaluatorOptions{0, 60.0});
    const EvolveConfig config = testing::synthetic_config(FitnessMethod::historical, 200, 3);
    std::string message;
    try {
      (void)run(config, evaluator);
    } catch (const MpiFailure& e) {
      message = std::string("MpiFailure: ") + e.what();
    } catch (const std::runtime_error& e) {
      message = e.what();
    }
    check(message.find("synthetic failure") != std::string::npos && message.rfind("rank ", 0) == 0,
          "an evaluation error reaches rank 0 naming the rank: '" + message + "'");
  }
  std::string message;
  try {
    MpiEvaluator evaluator(session, wire::Setup{wire::kProtocol, "no-such-kind", {}}, testing::synthetic_score,
                           MpiEvaluatorOptions{1, 60.0});
  } catch (const MpiFailure& e) {
    message = std::string("MpiFailure: ") + e.what();
  } catch (const std::runtime_error& e) {
    message = e.what();
  }
  check(session.size() == 1 || message.find("setting up the MPI ranks failed") != std::string::npos,
        "a setup the ranks cannot serve is an error: '" + message + "'");
}

void physics(MpiSession& session) {
  const std::string path = robot_path_named("superball").string();
  const Robot robot = load_robot(path);
  EvolveConfig config;
  config.teams = 5;
  config.episodes = 10;  // 2 generations
  config.population = 4;
  config.replace = 2;
  config.complexity = 3;
  config.period_s = 1.0;
  config.duration_s = 1.0;
  config.seed = 5;
  set_robot(config, robot);
  auto threaded = make_episode_evaluator(robot, config, 2);
  const Outcome reference = run(config, *threaded);
  std::FILE* f = std::fopen(path.c_str(), "rb");
  std::string text;
  for (int c; f != nullptr && (c = std::fgetc(f)) != EOF;) text.push_back(static_cast<char>(c));
  if (f != nullptr) std::fclose(f);
  MpiEvaluator evaluator(session, to_wire(episode_setup(text, config)), episode_team_function(robot, config),
                         MpiEvaluatorOptions{1, 120.0});
  const Outcome got = run(config, evaluator);
  check(got.curve == reference.curve && got.state == reference.state,
        "physics run equals the threaded run;" + loads(evaluator));
}

int main_rank0(MpiSession& session) {
  synthetic_runs(session);
  errors(session);
  physics(session);
  // The session's end tells the other ranks to stop.
  std::printf("%s: %d failure(s) on %d ranks\n", failures == 0 ? "PASS" : "FAIL", failures, session.size());
  return failures == 0 ? 0 : 1;
}

}  // namespace
}  // namespace tensegrity::sim::evolve

int main() {
  using namespace tensegrity::sim::evolve;
  int code = 0;
  try {
    MpiSession session;
    if (session.rank() == 0) {
      code = main_rank0(session);
    } else {
      serve_evaluations(session, session.rank(), factory);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mpi_evolve_check: %s\n", e.what());
    return 2;
  }
  return code;
}
