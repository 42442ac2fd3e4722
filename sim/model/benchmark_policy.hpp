// SPDX-License-Identifier: Apache-2.0
#pragma once
// The fixed benchmark workload, so that other simulators can run the same work:
// cable m prefers 0.85 + 0.15 sin(2 pi t / 4 + 2 pi m / 24) metres.
#include <vector>

#include "sim/model/controller.hpp"

namespace tensegrity::sim {

class BenchmarkController final : public Controller {
 public:
  void reset(const Robot& robot) override;
  void update(const ControlInput& input, std::span<double> preferred_rest_length_m) override;

 private:
  // sin(a + b_m) = sin a cos b_m + cos a sin b_m: two libm calls a step, not 24.
  std::vector<double> sin_phase_, cos_phase_;
};

}  // namespace tensegrity::sim
