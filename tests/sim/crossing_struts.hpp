// SPDX-License-Identifier: Apache-2.0
#pragma once
// Test fixture shared by model_test.cpp and engine_test.cpp: two crossing struts,
// one thrown at the other.
#include <algorithm>
#include <vector>

#include "sim/model/model.hpp"

namespace tensegrity::sim {

// Two struts crossing at right angles 0.3 m apart, joined by one slack cable: the
// smallest robot in which one strut can be thrown at another.
inline Robot crossing_struts(bool rod_contact) {
  const char* text = R"({
    "format": "tensegrity-robot/1", "name": "crossing", "gravity_m_per_s2": 9.81, "time_step_s": 0.001,
    "nodes_m": [[0, -0.5, 0], [0, 0.5, 0], [-0.5, 0, 0.3], [0.5, 0, 0.3]],
    "strut": {"mass_kg": 3.5, "radius_m": 0.0175},
    "struts": [[0, 1], [2, 3]],
    "cable": {"stiffness_n_per_m": 1000, "damping_n_s_per_m": 50, "initial_rest_length_m": 1.1,
              "min_rest_length_m": 0.6, "max_rest_length_m": 1.1, "motor_speed_m_per_s": 0.2,
              "cutoff_tension_n": 400, "hard_limit_tension_n": 500},
    "cables": [{"nodes": [0, 2], "owner": 0}],
    "ground": {"friction": 1.0, "contact_stiffness_n_per_m": 500000, "contact_damping_n_s_per_m": 2000},
    "start": {"clearance_m": 0.05, "settle_s": 0}
  })";
  Robot robot = parse_robot(text, "crossing.json");
  robot.rod_contact = rod_contact;
  return robot;
}

// Throws the upper strut down at 3 m/s for 0.3 s in free space; returns the smallest
// gap seen and the model for a look at the end state.
inline double throw_strut(Model& model) {
  model.set_gravity_enabled(false);
  model.set_ground_enabled(false);
  model.set_velocity(1, Eigen::Vector3d(0.0, 0.0, -3.0), Eigen::Vector3d::Zero());
  const std::vector<double> hold(1, 1.1);
  double min_gap = 1.0;
  for (int i = 0; i < 300; ++i) {
    model.step(hold);
    min_gap = std::min(min_gap, model.min_strut_gap_m());
  }
  return min_gap;
}

}  // namespace tensegrity::sim
