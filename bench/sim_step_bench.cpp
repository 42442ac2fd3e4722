// SPDX-License-Identifier: Apache-2.0
#include <benchmark/benchmark.h>
#include <ode/ode.h>

#include <algorithm>
#include <vector>

#include "sim/model/benchmark_policy.hpp"
#include "sim/model/episode.hpp"

namespace {

using namespace tensegrity::sim;

// Steps `robot` from its settled start, rest lengths held.
void step_settled(benchmark::State& state, const Robot& robot) {
  Model model(robot, 0.001);
  model.restore(settled_state(robot, 0.001));
  std::vector<double> preferred(robot.cables.size(), robot.initial_rest_length_m);
  for (auto _ : state) {
    model.step(preferred);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_ModelStep(benchmark::State& state) { step_settled(state, load_robot(robot_path_named("superball"))); }
BENCHMARK(BM_ModelStep);

// What the strut-gap measurement adds to every step, rod contact or not
// (sim/model/model_strut_contact.cpp): the closest points of the 15 strut pairs, here
// on the settled pose, beside BM_ModelStep above.
void BM_StrutGapMeasurement(benchmark::State& state) {
  const Robot robot = load_robot(robot_path_named("superball"));
  Model model(robot, 0.001);
  model.restore(settled_state(robot, 0.001));
  std::vector<dVector3> a(robot.struts.size()), b(robot.struts.size());
  for (std::size_t s = 0; s < robot.struts.size(); ++s) {
    const Eigen::Vector3d p = model.node_position(robot.struts[s].node_a);
    const Eigen::Vector3d q = model.node_position(robot.struts[s].node_b);
    for (int k = 0; k < 3; ++k) {
      a[s][k] = p[k];
      b[s][k] = q[k];
    }
    a[s][3] = b[s][3] = 0.0;
  }
  for (auto _ : state) {
    double min_gap = 1e9;
    for (std::size_t i = 0; i < a.size(); ++i) {
      for (std::size_t j = i + 1; j < a.size(); ++j) {
        dVector3 on_i, on_j;
        dClosestLineSegmentPoints(a[i], b[i], a[j], b[j], on_i, on_j);
        const double dx = on_i[0] - on_j[0], dy = on_i[1] - on_j[1], dz = on_i[2] - on_j[2];
        min_gap = std::min(min_gap, dx * dx + dy * dy + dz * dz);
      }
    }
    benchmark::DoNotOptimize(min_gap);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_StrutGapMeasurement);

// A step with rod contact on: the measurement plus any contact joints.
void BM_ModelStepRodContact(benchmark::State& state) {
  Robot robot = load_robot(robot_path_named("superball"));
  robot.rod_contact = true;
  Model model(robot, 0.001);
  model.restore(settled_state(load_robot(robot_path_named("superball")), 0.001));
  std::vector<double> preferred(robot.cables.size(), robot.initial_rest_length_m);
  for (auto _ : state) {
    model.step(preferred);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ModelStepRodContact);

// The same settled robot in the Bullet engine (robot.engine "bullet").
void BM_ModelStepBullet(benchmark::State& state) {
  Robot robot = load_robot(robot_path_named("superball"));
  robot.engine = Robot::PhysicsEngine::bullet;
  robot.hash += "-bullet";  // settled_state caches by hash
  step_settled(state, robot);
}
BENCHMARK(BM_ModelStepBullet);

void BM_BenchmarkEpisode10s(benchmark::State& state) {
  const Robot robot = load_robot(robot_path_named("superball"));
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
