// SPDX-License-Identifier: Apache-2.0
#include <benchmark/benchmark.h>

#include <array>

#include "core/endcap_controller.hpp"

namespace {

using namespace tensegrity::core;

void BM_EndcapControllerStep(benchmark::State& state) {
  EndcapController controller{EndcapConfig{}};
  EndcapTable table;
  table.motor_count = 2;
  table.complexity = 5;
  table.period_s = 4.0;
  for (auto& motor : table.rest_length_m) motor.fill(0.8);
  table.rest_length_m[0][2] = 1.0;
  controller.load(table);
  controller.start(0);
  std::array<double, 2> tension{60.0, 70.0};
  std::array<double, 2> out{};
  std::int64_t now = 0;
  for (auto _ : state) {
    controller.step(now, 0.001, tension, out);
    now += 1'000'000;
    benchmark::DoNotOptimize(out);
  }
}
BENCHMARK(BM_EndcapControllerStep);

}  // namespace
