// SPDX-License-Identifier: Apache-2.0
#pragma once
// How a controller drives the model: once per step it reads what the robot's sensors
// would (tensions, rest lengths) and sets each cable's preferred rest length. The
// model's actuators then move toward it at the motor speed. Nothing here knows about
// learning.
#include <cstdint>
#include <span>

namespace tensegrity::sim {

struct Robot;

struct ControlInput {
  std::int64_t step = 0;
  double time_s = 0.0;
  double dt_s = 0.0;
  std::span<const double> tension_n;      // per cable, as of the previous step
  std::span<const double> rest_length_m;  // per cable, current
};

class Controller {
 public:
  virtual ~Controller() = default;
  // Called once before the episode's first step.
  virtual void reset(const Robot& robot) = 0;
  virtual void update(const ControlInput& input, std::span<double> preferred_rest_length_m) = 0;
};

// Holds every cable at one preferred rest length.
class ConstantController final : public Controller {
 public:
  explicit ConstantController(double rest_length_m) : rest_length_m_(rest_length_m) {}
  void reset(const Robot&) override {}
  void update(const ControlInput&, std::span<double> preferred) override {
    for (double& p : preferred) p = rest_length_m_;
  }

 private:
  double rest_length_m_;
};

}  // namespace tensegrity::sim
