// SPDX-License-Identifier: Apache-2.0
#pragma once
// What a SUPERball offers the ground to steer by, emulated from the model with seeded
// noise: each end cap's accelerometer and an external position fix of the end caps'
// centre (a GNSS or motion-capture stand-in).
//
// An accelerometer reads the specific force (acceleration minus gravity: +g up at
// rest) in its end cap's frame: z along the strut, pointing out of the end cap; x and
// y turn with the strut. The acceleration is the end cap's mean over the time since
// the last reading, as a sensor's anti-alias filter would see it, plus white noise.
#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <random>
#include <vector>

#include "robot/robot.hpp"
#include "sim/model/model.hpp"

namespace tensegrity::sim {

struct SensorNoise {
  double acceleration_m_per_s2 = 0.3;  // per axis, per reading
  double fix_m = 0.1;                  // per horizontal axis, per fix
};

class EndcapSensors {
 public:
  EndcapSensors(const Robot& robot, std::uint64_t seed, const SensorNoise& noise);

  // Once after every model step: the end caps' velocities come from their positions.
  void observe(const Model& model);
  // One reading per end cap, m/s^2, in end cap order.
  std::vector<Eigen::Vector3d> accelerations(const Model& model);
  // The end caps' horizontal centre, world frame, with noise.
  Eigen::Vector2d fix(const Model& model);

 private:
  std::vector<int> other_end_;   // per end cap: the end cap at its strut's other end
  std::vector<int> strut_;       // per end cap: its strut
  std::vector<bool> first_end_;  // per end cap: node_a of its strut
  SensorNoise noise_;
  std::mt19937_64 random_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  static constexpr std::size_t kVelocitySteps = 10;
  std::deque<std::vector<Eigen::Vector3d>> history_;  // the last positions, oldest first
  std::vector<Eigen::Vector3d> velocity_, velocity_at_reading_;
  double time_s_ = 0.0, reading_time_s_ = 0.0;
};

}  // namespace tensegrity::sim
