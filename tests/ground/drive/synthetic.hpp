// SPDX-License-Identifier: Apache-2.0
#pragma once
// Synthetic accelerometer readings for a robot at rest in a known pose: every end cap
// reads +g up in its own frame (z out along its strut), plus seeded noise.
#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "ground/drive/face_geometry.hpp"
#include "robot/robot.hpp"

namespace tensegrity::drive::testing {

// The description turned so face `face` points down, then turned by `yaw_rad` about
// the vertical: description -> world.
inline Eigen::Matrix3d pose(const std::vector<sim::HullFace>& faces, int face, double yaw_rad) {
  return Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
         sim::face_down_turn(faces[face].normal);
}

inline std::vector<Eigen::Vector3d> readings(const sim::Robot& robot, const Eigen::Matrix3d& body, double noise,
                                             std::mt19937_64& random) {
  std::normal_distribution<double> normal(0.0, noise);
  std::vector<Eigen::Vector3d> out(robot.node_count());
  for (const auto& s : robot.struts) {
    for (int end = 0; end < 2; ++end) {
      const int self = end == 0 ? s.node_a : s.node_b;
      const int other = end == 0 ? s.node_b : s.node_a;
      const Eigen::Vector3d z = body * (robot.nodes_m[self] - robot.nodes_m[other]).normalized();
      // Any x square to z: the strut's spin about its axis is not known to the ground.
      Eigen::Vector3d x = z.unitOrthogonal();
      const Eigen::Vector3d y = z.cross(x);
      const Eigen::Vector3d up(0.0, 0.0, kGravity_m_per_s2);
      out[self] = Eigen::Vector3d(x.dot(up), y.dot(up), z.dot(up)) +
                  Eigen::Vector3d(normal(random), normal(random), normal(random));
    }
  }
  return out;
}

}  // namespace tensegrity::drive::testing
