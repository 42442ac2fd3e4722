// SPDX-License-Identifier: Apache-2.0
#include <benchmark/benchmark.h>

#include "sim/benchmark_policy.hpp"
#include "sim/episode.hpp"

namespace {

using namespace tensegrity::sim;

void BM_ModelStep(benchmark::State& state) {
  const Robot robot = load_robot(default_robot_path());
  Model model(robot, 0.001);
  model.restore(settled_state(robot, 0.001));
  std::vector<double> preferred(robot.cables.size(), robot.initial_rest_length_m);
  for (auto _ : state) {
    model.step(preferred);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ModelStep);

void BM_BenchmarkEpisode10s(benchmark::State& state) {
  const Robot robot = load_robot(default_robot_path());
  EpisodeOptions options;
  options.duration_s = 10.0;
  options.start = StartKind::drop;
  for (auto _ : state) {
    BenchmarkController controller;
    benchmark::DoNotOptimize(run_episode(robot, controller, options));
  }
}
BENCHMARK(BM_BenchmarkEpisode10s)->Unit(benchmark::kMillisecond);

}  // namespace
