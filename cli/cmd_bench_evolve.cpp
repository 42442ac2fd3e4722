// SPDX-License-Identifier: Apache-2.0
// `tensegrity bench evolve`: episodes per second during a short real evolution (the
// paper's defaults, physics on a thread pool), per core, and the speed-up over one
// thread. Also checks on the way that both runs gave the same curve.
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <thread>

#include "cli/commands.hpp"
#include "cli/episode_cli.hpp"
#include "sim/evolve/curve_csv.hpp"
#include "sim/evolve/driver.hpp"
#include "sim/evolve/episode_evaluator.hpp"
#include "sim/evolve/randomized_evaluator.hpp"

namespace tensegrity::cli {
namespace {

struct BenchEvolveArgs {
  std::string robot;
  std::int64_t episodes = 100;
  int threads = 0;
  double duration_s = 60.0;
  double dt_s = 0.0;      // 0: what `tensegrity evolve` scores at by default
  std::string randomize;  // robust learning's file; empty: the robot's own model
  int randomize_k = 8;
  bool json = false;
};

// As `tensegrity evolve --randomize FILE --randomize-k K` sets it.
void set_randomization(sim::evolve::EvolveConfig& config, const BenchEvolveArgs& args, const sim::Robot& robot) {
  if (args.randomize.empty()) return;
  try {
    config.randomization = sim::load_randomization(args.randomize).canonical;
    config.randomize_k = args.randomize_k;
    (void)sim::evolve::config_randomization(config, robot);
  } catch (const std::runtime_error& e) {
    throw CommandError(ExitCode::usage, std::string("--randomize: ") + e.what());
  }
}

// The targets: 5000 episodes in at most 3 minutes on the machine's cores.
constexpr double kTargetEpisodes = 5000.0;
constexpr double kTarget5000EpisodesWallS = 180.0;

// Resident memory now, kB (/proc/self/statm counts pages), so that a long run shows
// whether it grows; -1 where /proc is missing.
long resident_kb() {
  std::ifstream statm("/proc/self/statm");
  long size_pages = 0;
  long resident_pages = 0;
  if (!(statm >> size_pages >> resident_pages)) return -1;
  return resident_pages * (sysconf(_SC_PAGESIZE) / 1024);
}

long peak_resident_kb() {
  rusage usage{};
  return getrusage(RUSAGE_SELF, &usage) == 0 ? usage.ru_maxrss : -1;
}

struct Timed {
  double wall_s = 0.0;
  double episodes_per_s = 0.0;
  std::string curve;
};

Timed time_run(const sim::Robot& robot, const sim::evolve::EvolveConfig& config, int threads) {
  auto evaluator = sim::evolve::make_episode_evaluator(robot, config, threads);
  const auto t0 = std::chrono::steady_clock::now();
  auto result = sim::evolve::drive(config, *evaluator, {});
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return Timed{wall, static_cast<double>(result.evolution.episodes()) / wall,
               sim::evolve::curve_csv(result.evolution.curve())};
}

void run_bench_evolve(const BenchEvolveArgs& args) {
  const sim::Robot robot = load_robot_arg(args.robot);
  const unsigned hw = std::thread::hardware_concurrency();
  const int threads = args.threads > 0 ? args.threads : (hw == 0 ? 1 : static_cast<int>(hw));
  sim::evolve::EvolveConfig config;
  config.episodes = args.episodes;
  config.duration_s = args.duration_s;
  sim::evolve::set_robot(config, robot);
  config.dt_s = args.dt_s > 0.0 ? args.dt_s : sim::evolve::default_learning_dt_s(robot);
  sim::evolve::set_default_early_end(config, robot);
  set_randomization(config, args, robot);
  const double dt_s = config.dt_s > 0.0 ? config.dt_s : robot.time_step_s;
  // The settled start is computed once per process; keep it out of the timing.
  (void)sim::settled_state(robot, dt_s);

  const Timed many = time_run(robot, config, threads);
  Timed one;
  if (threads > 1) one = time_run(robot, config, 1);
  const double per_core = many.episodes_per_s / threads;
  const bool identical = threads == 1 || one.curve == many.curve;
  const double projected_s = kTargetEpisodes / many.episodes_per_s;
  if (args.json) {
    nlohmann::json j = {{"benchmark", "evolve"},
                        {"episodes", args.episodes},
                        {"duration_s", args.duration_s},
                        {"dt_s", dt_s},
                        {"early_end_bar_m", config.early_end_bar_m},
                        {"threads", threads},
                        {"randomize_k", config.randomization.empty() ? 0 : config.randomize_k},
                        {"wall_s", many.wall_s},
                        {"episodes_per_s", many.episodes_per_s},
                        {"episodes_per_s_per_core", per_core},
                        {"projected_5000_episodes_wall_s", projected_s},
                        {"target_5000_episodes_wall_s", kTarget5000EpisodesWallS},
                        {"ratio_to_target", kTarget5000EpisodesWallS / projected_s},
                        {"rss_kb", resident_kb()},
                        {"max_rss_kb", peak_resident_kb()}};
    if (threads > 1) {
      j["one_thread_episodes_per_s"] = one.episodes_per_s;
      j["speedup_over_one_thread"] = many.episodes_per_s / one.episodes_per_s;
      j["parallel_efficiency"] = many.episodes_per_s / one.episodes_per_s / threads;
      j["identical_to_one_thread"] = identical;
    }
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("bench evolve: %lld episodes of %.0f s at dt %.4g s (teams of 50, historical), %d threads\n",
                static_cast<long long>(args.episodes), args.duration_s, dt_s, threads);
    if (!config.randomization.empty()) {
      std::printf("  every team on %d sampled models (%s): %d physics episodes per team\n", config.randomize_k,
                  args.randomize.c_str(), config.randomize_k);
    }
    std::printf("  %.2f episodes/s, %.2f per core, %.1f s wall\n", many.episodes_per_s, per_core, many.wall_s);
    std::printf("  5000 episodes would take %.0f s; target %.0f s, ratio %.2f\n", projected_s, kTarget5000EpisodesWallS,
                kTarget5000EpisodesWallS / projected_s);
    std::printf("  resident memory %ld kB now, %ld kB at most\n", resident_kb(), peak_resident_kb());
    if (threads > 1) {
      std::printf("  1 thread: %.2f episodes/s; speed-up %.2fx (efficiency %.0f%%); same curve: %s\n",
                  one.episodes_per_s, many.episodes_per_s / one.episodes_per_s,
                  100.0 * many.episodes_per_s / one.episodes_per_s / threads, identical ? "yes" : "NO");
    }
  }
  if (!identical) throw CommandError(ExitCode::failure, "bench evolve: the curve depends on the thread count");
}

}  // namespace

void add_bench_evolve_command(CLI::App& bench) {
  auto args = std::make_shared<BenchEvolveArgs>();
  CLI::App* cmd = bench.add_subcommand("evolve", "Episodes per second during evolution, per core and vs one thread");
  cmd->add_option("--robot", args->robot, "Robot description")->check(CLI::ExistingFile);
  cmd->add_option("--episodes", args->episodes, "Episodes to run (50 per generation)")
      ->capture_default_str()
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1000000}));
  cmd->add_option("--threads", args->threads, "Worker threads (default: all cores)")->check(CLI::Range(1, 1024));
  cmd->add_option("--duration", args->duration_s, "Episode length, seconds")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 3600.0));
  cmd->add_option("--dt", args->dt_s,
                  "Time step teams are scored at, seconds (default: as `tensegrity evolve`, the robot's learning step)")
      ->check(CLI::Range(1e-5, 0.01));
  CLI::Option* file = cmd->add_option("--randomize", args->randomize,
                                      "Score every team on sampled models from this randomization file, as "
                                      "`tensegrity evolve --randomize`")
                          ->check(CLI::ExistingFile);
  cmd->add_option("--randomize-k", args->randomize_k, "With --randomize: sampled models per team")
      ->capture_default_str()
      ->check(CLI::Range(1, sim::evolve::kMaxRandomizeK))
      ->needs(file);
  cmd->add_flag("--json", args->json, "Print one JSON object");
  cmd->callback([args] { run_bench_evolve(*args); });
}

}  // namespace tensegrity::cli
