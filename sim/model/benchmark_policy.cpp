// SPDX-License-Identifier: Apache-2.0
#include "sim/model/benchmark_policy.hpp"

#include <cmath>
#include <numbers>

#include "robot/robot.hpp"

namespace tensegrity::sim {

void BenchmarkController::reset(const Robot& robot) {
  const int n = robot.cable_count();
  sin_phase_.resize(n);
  cos_phase_.resize(n);
  for (int m = 0; m < n; ++m) {
    const double b = 2.0 * std::numbers::pi * m / 24.0;
    sin_phase_[m] = std::sin(b);
    cos_phase_[m] = std::cos(b);
  }
}

void BenchmarkController::update(const ControlInput& input, std::span<double> preferred) {
  const double a = 2.0 * std::numbers::pi * input.time_s / 4.0;
  const double sa = std::sin(a);
  const double ca = std::cos(a);
  for (std::size_t m = 0; m < preferred.size(); ++m) {
    preferred[m] = 0.85 + 0.15 * (sa * cos_phase_[m] + ca * sin_phase_[m]);
  }
}

}  // namespace tensegrity::sim
