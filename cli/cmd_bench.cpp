// SPDX-License-Identifier: Apache-2.0
// `tensegrity bench sim`: the benchmark episode (60 s, from the drop start) N times
// on one thread, at the step asked for, and the same episode at 1 ms in the robot's
// ODE model and in the Bullet engine's model of the same robot, played in turns so
// that both see the same load.
#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <vector>

#include "cli/commands.hpp"
#include "cli/episode_cli.hpp"
#include "sim/model/benchmark_policy.hpp"
#include "sim/model/episode.hpp"

namespace tensegrity::cli {
namespace {

// The targets: the learning step at 1000x real time on one core, and at 1 ms 3.5x
// the speed of a Bullet model of the same robot.
constexpr double kTargetRealTimeFactor = 1000.0;
constexpr double kTargetSpeedupOverBullet = 3.5;
constexpr double kPeerStepS = 0.001;

struct BenchSimArgs {
  std::string robot;
  int episodes = 10;
  double duration_s = 60.0;
  double dt_s = 0.001;
  bool bullet = true;
  bool json = false;
};

struct Timing {
  std::vector<double> wall_s;
  double distance_m = 0.0;
  double min_s() const { return *std::min_element(wall_s.begin(), wall_s.end()); }
  double median_s() const {
    std::vector<double> sorted = wall_s;
    std::sort(sorted.begin(), sorted.end());
    const std::size_t n = sorted.size();
    return n % 2 == 1 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
  }
};

void time_episode(const sim::Robot& robot, double dt_s, double duration_s, Timing& timing) {
  sim::EpisodeOptions options;
  options.duration_s = duration_s;
  options.dt_s = dt_s;
  options.start = sim::StartKind::drop;
  sim::BenchmarkController controller;
  const auto result = sim::run_episode(robot, controller, options);
  timing.wall_s.push_back(result.wall_time_s);
  timing.distance_m = result.distance_m;
}

nlohmann::json timing_json(const Timing& t, double duration_s) {
  return {{"min_wall_s", t.min_s()},
          {"median_wall_s", t.median_s()},
          {"real_time_factor", duration_s / t.median_s()},
          {"distance_m", t.distance_m}};
}

void run_bench_sim(const BenchSimArgs& args) {
  const sim::Robot robot = load_robot_arg(args.robot);
  sim::Robot bullet = robot;
  bullet.engine = sim::Robot::PhysicsEngine::bullet;
  const bool peer_step = args.dt_s == kPeerStepS;
  Timing main, ode_1ms, bullet_1ms;
  for (int i = 0; i < args.episodes; ++i) {
    time_episode(robot, args.dt_s, args.duration_s, main);
    if (args.bullet && !peer_step) time_episode(robot, kPeerStepS, args.duration_s, ode_1ms);
    if (args.bullet) time_episode(bullet, kPeerStepS, args.duration_s, bullet_1ms);
    if (!args.json) std::fprintf(stderr, "\repisode %d/%d: %.4f s", i + 1, args.episodes, main.wall_s.back());
  }
  if (!args.json) std::fprintf(stderr, "\n");
  if (peer_step) ode_1ms = main;
  const double rtf = args.duration_s / main.median_s();
  nlohmann::json j = {{"benchmark", "sim"},
                      {"robot", robot.name},
                      {"episodes", args.episodes},
                      {"sim_time_s", args.duration_s},
                      {"dt_s", args.dt_s},
                      {"min_wall_s", main.min_s()},
                      {"median_wall_s", main.median_s()},
                      {"real_time_factor", rtf},
                      {"best_real_time_factor", args.duration_s / main.min_s()},
                      {"target_real_time_factor", kTargetRealTimeFactor},
                      {"ratio_to_target", rtf / kTargetRealTimeFactor},
                      {"distance_m", main.distance_m}};
  if (args.bullet) {
    const double speedup = bullet_1ms.median_s() / ode_1ms.median_s();
    j["at_1ms"] = {{"ode", timing_json(ode_1ms, args.duration_s)},
                   {"bullet", timing_json(bullet_1ms, args.duration_s)},
                   {"speedup_over_bullet", speedup},
                   {"target_speedup_over_bullet", kTargetSpeedupOverBullet},
                   {"ratio_to_target", speedup / kTargetSpeedupOverBullet}};
  }
  if (args.json) {
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf("bench sim: %s, %d episodes of %.0f s at dt %.4g s, one thread\n", robot.name.c_str(), args.episodes,
              args.duration_s, args.dt_s);
  std::printf("  wall per episode  min %.4f s, median %.4f s\n", main.min_s(), main.median_s());
  std::printf("  real-time factor  %.0fx (median), %.0fx (best); target %.0fx, ratio %.2f\n", rtf,
              args.duration_s / main.min_s(), kTargetRealTimeFactor, rtf / kTargetRealTimeFactor);
  if (args.bullet) {
    const double speedup = bullet_1ms.median_s() / ode_1ms.median_s();
    std::printf("  at 1 ms: this model %.4f s, Bullet engine %.4f s (median): %.2fx; target %.1fx, ratio %.2f\n",
                ode_1ms.median_s(), bullet_1ms.median_s(), speedup, kTargetSpeedupOverBullet,
                speedup / kTargetSpeedupOverBullet);
  }
}

}  // namespace

void add_bench_command(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks that print numbers and ratios");
  bench->require_subcommand(1);
  auto args = std::make_shared<BenchSimArgs>();
  CLI::App* sim_cmd =
      bench->add_subcommand("sim", "Benchmark policy, 60 s, N episodes on one thread; against Bullet at 1 ms");
  sim_cmd->add_option("--robot", args->robot, "Robot description")->check(CLI::ExistingFile);
  sim_cmd->add_option("--episodes", args->episodes, "Episodes to time")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  sim_cmd->add_option("--duration", args->duration_s, "Episode length, seconds")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 3600.0));
  sim_cmd->add_option("--dt", args->dt_s, "Time step, seconds")->capture_default_str()->check(CLI::Range(1e-5, 0.01));
  sim_cmd->add_flag("!--no-bullet", args->bullet, "Skip the comparison with the Bullet engine at 1 ms");
  sim_cmd->add_flag("--json", args->json, "Print one JSON object");
  sim_cmd->callback([args] { run_bench_sim(*args); });
  add_bench_evolve_command(*bench);
  add_bench_hil_command(*bench);
}

}  // namespace tensegrity::cli
