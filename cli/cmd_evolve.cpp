// SPDX-License-Identifier: Apache-2.0
// `tensegrity evolve`: cooperative coevolution of a policy on the model (paper,
// Algorithm 1), checkpointed after every generation, resumable after any kill;
// evaluated on threads, or with --mpi on the ranks of an MPI job (cli/evolve_mpi).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "cli/commands.hpp"
#include "cli/evolve_mpi.hpp"
#include "cli/evolve_progress.hpp"
#include "sim/evolve/checkpoint.hpp"
#include "sim/evolve/episode_evaluator.hpp"
#include "sim/evolve/evolve_run.hpp"

namespace tensegrity::cli {
namespace {

// The use case's options (sim/evolve/evolve_run.hpp), and how this process runs it.
struct EvolveArgs {
  sim::evolve::EvolveRequest request;
  int threads = 0;
  std::string checkpoint;
  bool resume = false;
  std::string robot;
  std::string out;
  std::string log;
  bool json = false;
  bool mpi = false;
  int mpi_root_threads = -1;
  double mpi_timeout_s = 600.0;
};

int default_threads() {
  const unsigned n = std::thread::hardware_concurrency();
  return n == 0 ? 1 : static_cast<int>(n);
}

// The description's text as well as the robot: MPI ranks get the text, so that they
// need no copy of the file and cannot read a different one.
struct RobotArg {
  std::string text;
  sim::Robot robot;
};

RobotArg read_robot_arg(const std::string& arg) {
  const std::filesystem::path path = arg.empty() ? sim::default_robot_path() : std::filesystem::path(arg);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw CommandError(ExitCode::usage, path.string() + ": cannot open robot description");
  std::ostringstream text;
  text << in.rdbuf();
  try {
    sim::Robot robot = sim::parse_robot(text.str(), path.string());
    return RobotArg{text.str(), std::move(robot)};
  } catch (const sim::RobotError& e) {
    throw CommandError(ExitCode::usage, e.what());
  }
}

sim::evolve::EvolveConfig evolve_config(const EvolveArgs& args, const sim::Robot& robot) {
  try {
    return sim::evolve::request_config(args.request, robot);
  } catch (const sim::evolve::ConfigError& e) {
    throw CommandError(ExitCode::usage, e.what());
  }
}

// What the summary shows beside the evolution itself.
struct EvolveSummary {
  sim::evolve::EvolveOutcome run;
  int threads = 0;
};

void print_json(const EvolveArgs& args, const sim::evolve::EvolveConfig& config, const EvolveSummary& summary,
                EvolveMpi* mpi) {
  const sim::evolve::EvolveOutcome& o = summary.run;
  const auto& evo = o.result.evolution;
  const std::int64_t episodes_here = evo.episodes() - o.result.resumed_episodes;
  nlohmann::json j = {{"best_score_m", evo.best().score_m},
                      {"best_feasible", evo.best().feasible},
                      {"final_score_m", o.final_result.score_m},
                      {"final_feasible", o.final_result.feasible},
                      {"robot_step_score_m", o.gait.feasible ? o.gait.distance_m : 0.0},
                      {"episodes", evo.episodes()},
                      {"generations", evo.generation()},
                      {"infeasible_rate_last", evo.curve().empty() ? 0.0 : evo.curve().back().infeasible_rate()},
                      {"resumed", o.result.resumed},
                      {"threads", summary.threads},
                      {"ranks", mpi != nullptr ? mpi->ranks() : 1},
                      {"wall_time_s", o.wall_s},
                      {"episodes_per_s", o.wall_s > 0.0 ? static_cast<double>(episodes_here) / o.wall_s : 0.0},
                      {"out", args.out},
                      {"log", args.log},
                      {"config", sim::evolve::config_to_json(config)},
                      {"gait",
                       {{"axial_spin_rms_rad_per_s", o.gait.axial_spin_rms_rad_per_s},
                        {"axial_spin_max_rad_per_s", o.gait.axial_spin_max_rad_per_s},
                        {"endcaps_touched_ground", o.gait.endcaps_touched_ground},
                        {"min_strut_gap_m", o.gait.min_strut_gap_m},
                        {"strut_overlap_s", o.gait.strut_overlap_s},
                        {"heading_deg", o.gait.travel.heading_deg ? nlohmann::json(*o.gait.travel.heading_deg)
                                                                  : nlohmann::json(nullptr)}}}};
  if (mpi != nullptr) j["rank_loads"] = mpi->loads();
  std::printf("%s\n", j.dump(2).c_str());
}

void print_text(const EvolveArgs& args, const sim::evolve::EvolveConfig& config, const EvolveSummary& summary,
                EvolveMpi* mpi) {
  const sim::evolve::EvolveOutcome& o = summary.run;
  const auto& evo = o.result.evolution;
  const auto& best = evo.best();
  const std::int64_t episodes_here = evo.episodes() - o.result.resumed_episodes;
  const double rate = o.wall_s > 0.0 ? static_cast<double>(episodes_here) / o.wall_s : 0.0;
  const double infeasible_last = evo.curve().empty() ? 0.0 : evo.curve().back().infeasible_rate();
  std::printf("evolve %s: %d generations, %lld episodes%s\n", sim::evolve::to_string(config.method), evo.generation(),
              static_cast<long long>(evo.episodes()), o.result.resumed ? " (resumed)" : "");
  std::printf("  best team  %.3f m (generation %d), re-evaluated %.3f m%s\n", best.score_m, best.generation,
              o.final_result.score_m, o.final_result.feasible ? "" : " INFEASIBLE");
  if (config.dt_s > 0.0) {
    std::printf("  scored at dt %.4g s; at the robot's own step it rolls %.3f m%s (the policy's score)\n", config.dt_s,
                o.gait.distance_m, o.gait.feasible ? "" : " INFEASIBLE");
  }
  if (!config.randomization.empty()) {
    std::printf(
        "  models     %d sampled per team from %s, new every generation; score %s (re-evaluated on "
        "the next generation's)\n",
        config.randomize_k, args.request.randomize.c_str(), sim::evolve::to_string(config.randomize_score));
  }
  std::printf("  infeasible %.0f%% in the last generation\n", 100.0 * infeasible_last);
  std::printf("  gait       strut spin %.2f rad/s RMS, %.2f max; %d end caps touched the ground\n",
              o.gait.axial_spin_rms_rad_per_s, o.gait.axial_spin_max_rad_per_s, o.gait.endcaps_touched_ground);
  std::printf("  struts     %.3f m apart at the closest, overlapping for %.2f s\n", o.gait.min_strut_gap_m,
              o.gait.strut_overlap_s);
  if (o.gait.travel.heading_deg) std::printf("  heading    %+.1f deg in the start frame\n", *o.gait.travel.heading_deg);
  std::printf("  time       %.1f s wall, %.2f episodes/s on %d threads", o.wall_s, rate, summary.threads);
  if (mpi != nullptr) std::printf(" over %d MPI ranks", mpi->ranks());
  std::printf("\n");
  if (mpi != nullptr) {
    for (const auto& r : mpi->loads()) {
      std::printf("    rank %d  %-20s %3d threads  %lld teams\n", r["rank"].get<int>(),
                  r["host"].get<std::string>().c_str(), r["threads"].get<int>(), r["teams"].get<long long>());
    }
  }
  std::printf("  policy     %s\n  curve      %s\n", args.out.c_str(), args.log.c_str());
}

// Evolves (sim/evolve/evolve_run.hpp) with the progress line on a terminal.
sim::evolve::EvolveOutcome evolve(const EvolveArgs& args, const sim::Robot& robot,
                                  const sim::evolve::EvolveConfig& config, sim::evolve::Evaluator& evaluator) {
  EvolveProgress progress(isatty(STDERR_FILENO) == 1, config.episodes);
  const sim::evolve::RunFiles files{args.out, args.log, args.checkpoint, args.resume};
  try {
    sim::evolve::EvolveOutcome o =
        sim::evolve::run_evolution(robot, config, evaluator, files,
                                   [&](const sim::evolve::Coevolution& evo, const sim::evolve::GenerationStats& stats) {
                                     progress.update(evo, stats);
                                   });
    progress.finish();
    for (const auto& w : o.result.warnings) std::fprintf(stderr, "tensegrity: warning: %s\n", w.c_str());
    return o;
  } catch (const sim::evolve::CheckpointError& e) {
    progress.finish();
    throw CommandError(ExitCode::checkpoint, e.what());
  }
}

// `mpi` is rank 0's side of an MPI run; null: evaluate on this machine's threads.
void run_evolve(const EvolveArgs& args, EvolveMpi* mpi) {
  const RobotArg robot_arg = read_robot_arg(args.robot);
  const sim::Robot& robot = robot_arg.robot;
  const sim::evolve::EvolveConfig config = evolve_config(args, robot);
  std::unique_ptr<sim::evolve::Evaluator> threaded;
  int threads = 0;
  if (mpi == nullptr) {
    threads = args.threads > 0 ? args.threads : default_threads();
    threaded = sim::evolve::make_episode_evaluator(robot, config, threads);
  }
  sim::evolve::Evaluator& evaluator = mpi != nullptr ? mpi->evaluator(robot_arg.text, robot, config) : *threaded;
  if (mpi != nullptr) threads = mpi->threads();
  const EvolveSummary summary{evolve(args, robot, config, evaluator), threads};
  if (args.json) {
    print_json(args, config, summary, mpi);
  } else {
    print_text(args, config, summary, mpi);
  }
}

// The mutation operator and its step's schedule.
void add_mutation_options(CLI::App& cmd, EvolveArgs& args) {
  cmd.add_option("--mutation", args.request.mutation,
                 "Mutation operator: gaussian (every value of a copy) or author (NTRT's: half the copies, half "
                 "their values)")
      ->capture_default_str()
      ->check(CLI::IsMember({"author", "gaussian"}));
  cmd.add_option("--sigma", args.request.sigma_m,
                 "Mutation step, metres, clamped to the limits (default for gaussian: 0.05, annealed to 0.02 "
                 "over episodes 2000-5000 unless a step option is given; for author: 0.03 of the rest-length "
                 "range, constant)")
      ->check(CLI::Range(0.0, 10.0));
  // The schedule's three options go together: a step given without its episodes
  // (or the reverse) would be silently ignored.
  CLI::Option* sigma_final =
      cmd.add_option("--sigma-final", args.request.sigma_final_m,
                     "Mutation step after --anneal-episodes, metres (default: no annealing once any step option "
                     "is given)")
          ->check(CLI::Range(0.0, 10.0));
  CLI::Option* anneal = cmd.add_option("--anneal-episodes", args.request.anneal_episodes,
                                       "Episodes over which the step goes geometrically from --sigma to --sigma-final")
                            ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 40));
  CLI::Option* anneal_start = cmd.add_option("--anneal-start", args.request.anneal_start_episodes,
                                             "Episodes at the constant --sigma before annealing begins (default 0)")
                                  ->check(CLI::Range(std::int64_t{0}, std::int64_t{1} << 40));
  sigma_final->needs(anneal);
  anneal->needs(sigma_final);
  anneal_start->needs(anneal);
}

// --mpi and what it needs.
void add_mpi_options(CLI::App& cmd, EvolveArgs& args) {
  cmd.add_flag("--mpi", args.mpi,
               "Evaluate on the ranks of an MPI job (mpirun -np N tensegrity evolve ... --mpi): rank 0 evolves, "
               "the others only evaluate; results do not depend on it");
  cmd.add_option("--mpi-root-threads", args.mpi_root_threads,
                 "With --mpi: rank 0's evaluating threads (default: --threads; 0: rank 0 only hands out teams)")
      ->check(CLI::Range(0, 1024));
  cmd.add_option("--mpi-timeout", args.mpi_timeout_s,
                 "With --mpi: fail the run when a rank holding a team answers nothing for this many seconds "
                 "(0: wait forever)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e7));
}

// Robust learning: teams scored on sampled models.
void add_randomize_options(CLI::App& cmd, EvolveArgs& args) {
  CLI::Option* file = cmd.add_option("--randomize", args.request.randomize,
                                     "Score every team on sampled models drawn from this randomization file "
                                     "(tensegrity-randomization/1; new samples every generation, the same for "
                                     "every team of one)");
  cmd.add_option("--randomize-k", args.request.randomize_k, "With --randomize: sampled models per team")
      ->capture_default_str()
      ->check(CLI::Range(1, sim::evolve::kMaxRandomizeK))
      ->needs(file);
  cmd.add_option("--randomize-score", args.request.randomize_score,
                 "With --randomize: a team's score from its samples' distances: mean, or q25 (the lower quartile)")
      ->capture_default_str()
      ->check(CLI::IsMember({"mean", "q25"}))
      ->needs(file);
}

}  // namespace

void add_evolve_command(CLI::App& app) {
  auto args = std::make_shared<EvolveArgs>();
  CLI::App* cmd =
      app.add_subcommand("evolve", "Coevolve a rolling policy (cooperative coevolution, paper Algorithm 1)");
  cmd->add_option("--period", args->request.period_s, "Signal period, seconds")
      ->capture_default_str()
      ->check(CLI::Range(0.01, 3600.0));
  cmd->add_option("--complexity", args->request.complexity, "Values per cable signal")
      ->capture_default_str()
      ->check(CLI::Range(1, 16));
  cmd->add_option("--method", args->request.method, "Fitness: historical|leniency|average")
      ->capture_default_str()
      ->check(CLI::IsMember({"historical", "leniency", "average"}));
  cmd->add_option("--episodes", args->request.episodes, "Episode budget")
      ->capture_default_str()
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 40));
  cmd->add_option("--seed", args->request.seed, "Random seed (the run depends on it alone)")->capture_default_str();
  cmd->add_option("--threads", args->threads,
                  "Worker threads (default: all cores; with --mpi per rank, the CPUs it may use); results do not "
                  "depend on it")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--checkpoint", args->checkpoint, "Directory for a checkpoint after every generation");
  cmd->add_flag("--resume", args->resume,
                "Continue the run checkpointed in --checkpoint (a larger --episodes extends a finished run)");
  // Not checked by the parser: with --mpi only rank 0 reads it, the other machines need no copy.
  cmd->add_option("--robot", args->robot,
                  "Robot description (default: robots/superball-paper.json, the paper's model)");
  cmd->add_option("--population", args->request.population, "Members per cable population")
      ->capture_default_str()
      ->check(CLI::Range(2, 100000));
  cmd->add_option("--teams", args->request.teams, "Random teams per generation")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--replace", args->request.replace, "Worst members replaced per generation")
      ->capture_default_str()
      ->check(CLI::Range(1, 50000));
  add_mutation_options(*cmd, *args);
  cmd->add_option("--duration", args->request.duration_s, "Episode length, seconds")
      ->capture_default_str()
      ->check(CLI::Range(0.01, 3600.0));
  cmd->add_option("--dt", args->request.dt_s,
                  "Time step teams are scored at, seconds (default: the robot's learning.time_step_s, else its "
                  "time_step_s; docs/design/performance.md)")
      ->check(CLI::Range(1e-5, 0.01));
  cmd->add_option("--early-end", args->request.early_end_m,
                  "End a team's episode once it provably cannot roll this many metres (default: the robot's "
                  "learning.early_end.bar_m; 0: every episode runs to its end; docs/design/performance.md)")
      ->check(CLI::Range(0.0, 1000.0));
  cmd->add_option("--out", args->out, "Policy file of the best team")->required();
  cmd->add_option("--log", args->log, "Learning curve CSV")->required();
  cmd->add_flag("--json", args->json, "Print a JSON summary");
  add_mpi_options(*cmd, *args);
  add_randomize_options(*cmd, *args);
  cmd->callback([args] {
    if (args->resume && args->checkpoint.empty())
      throw CommandError(ExitCode::usage, "--resume needs --checkpoint DIR");
    if (args->mpi && !args->request.randomize.empty()) {
      throw CommandError(ExitCode::usage,
                         "--randomize is not sent to MPI ranks (they would score the robot's own model): run it "
                         "without --mpi, on --threads");
    }
    check_evolve_launch(args->mpi);
    if (!args->mpi) {
      run_evolve(*args, nullptr);
      return;
    }
    const EvolveMpiArgs mpi_args{args->threads, args->mpi_root_threads, args->mpi_timeout_s};
    run_evolve_mpi(mpi_args, [&](EvolveMpi& mpi) { run_evolve(*args, &mpi); });
  });
}

}  // namespace tensegrity::cli
