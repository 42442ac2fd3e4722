// SPDX-License-Identifier: Apache-2.0
// `tensegrity bench sim`: the benchmark episode (60 s at 1 ms) N times on one thread.
#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <vector>

#include "cli/commands.hpp"
#include "cli/episode_json.hpp"
#include "sim/benchmark_policy.hpp"
#include "sim/episode.hpp"

namespace tensegrity::cli {
namespace {

struct BenchSimArgs {
  std::string robot;
  int episodes = 10;
  double duration_s = 60.0;
  bool json = false;
};

void run_bench_sim(const BenchSimArgs& args) {
  const sim::Robot robot = load_robot_arg(args.robot);
  sim::EpisodeOptions options;
  options.duration_s = args.duration_s;
  options.dt_s = 0.001;
  options.start = sim::StartKind::drop;
  std::vector<double> wall;
  double distance = 0.0;
  for (int i = 0; i < args.episodes; ++i) {
    sim::BenchmarkController controller;
    const auto result = sim::run_episode(robot, controller, options);
    wall.push_back(result.wall_time_s);
    distance = result.distance_m;
    if (!args.json) {
      std::fprintf(stderr, "\repisode %d/%d: %.4f s", i + 1, args.episodes, result.wall_time_s);
    }
  }
  if (!args.json) std::fprintf(stderr, "\n");
  std::vector<double> sorted = wall;
  std::sort(sorted.begin(), sorted.end());
  const double min = sorted.front();
  const double median = sorted.size() % 2 == 1 ? sorted[sorted.size() / 2]
                                               : 0.5 * (sorted[sorted.size() / 2 - 1] + sorted[sorted.size() / 2]);
  const double rtf = args.duration_s / median;
  if (args.json) {
    const nlohmann::json j = {{"benchmark", "sim"},
                              {"episodes", args.episodes},
                              {"sim_time_s", args.duration_s},
                              {"dt_s", options.dt_s},
                              {"min_wall_s", min},
                              {"median_wall_s", median},
                              {"real_time_factor", rtf},
                              {"best_real_time_factor", args.duration_s / min},
                              {"target_real_time_factor", 1000.0},
                              {"ratio_to_target", rtf / 1000.0},
                              {"distance_m", distance}};
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("bench sim: %d episodes of %.0f s at dt 1 ms, one thread\n", args.episodes, args.duration_s);
    std::printf("  wall per episode  min %.4f s, median %.4f s\n", min, median);
    std::printf("  real-time factor  %.0fx (median), %.0fx (best); target 1000x, ratio %.2f\n", rtf,
                args.duration_s / min, rtf / 1000.0);
  }
}

}  // namespace

void add_bench_command(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks that print numbers and ratios");
  bench->require_subcommand(1);
  auto args = std::make_shared<BenchSimArgs>();
  CLI::App* sim_cmd = bench->add_subcommand("sim", "Benchmark policy, 60 s at dt 1 ms, N episodes on one thread");
  sim_cmd->add_option("--robot", args->robot, "Robot description")->check(CLI::ExistingFile);
  sim_cmd->add_option("--episodes", args->episodes, "Episodes to time")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  sim_cmd->add_option("--duration", args->duration_s, "Episode length, seconds")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 3600.0));
  sim_cmd->add_flag("--json", args->json, "Print one JSON object");
  sim_cmd->callback([args] { run_bench_sim(*args); });
  add_bench_evolve_command(*bench);
  add_bench_hil_command(*bench);
}

}  // namespace tensegrity::cli
