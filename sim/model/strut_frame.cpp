// SPDX-License-Identifier: Apache-2.0
#include "sim/model/strut_frame.hpp"

#include <Eigen/Geometry>

namespace tensegrity::sim {

Eigen::Matrix3d strut_frame(std::span<const Eigen::Vector3d> nodes_m, int node_a, int node_b) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& n : nodes_m) centre += n;
  centre /= static_cast<double>(nodes_m.size());
  const Eigen::Vector3d z = (nodes_m[node_b] - nodes_m[node_a]).normalized();
  Eigen::Vector3d x = centre - 0.5 * (nodes_m[node_a] + nodes_m[node_b]);
  x -= x.dot(z) * z;
  // A strut through the centre has no preferred direction; any perpendicular will do.
  if (x.norm() < 1e-9) x = z.unitOrthogonal();
  x.normalize();
  Eigen::Matrix3d m;
  m.col(0) = x;
  m.col(1) = z.cross(x);
  m.col(2) = z;
  return m;
}

Eigen::Vector3d surface_attachment(const Robot& robot, int strut, int from, int to) {
  const auto& s = robot.struts[static_cast<std::size_t>(strut)];
  const Eigen::Matrix3d frame = strut_frame(robot.nodes_m, s.node_a, s.node_b);
  Eigen::Vector3d d = robot.nodes_m[to] - robot.nodes_m[from];
  d -= d.dot(frame.col(2)) * frame.col(2);
  if (d.norm() < 1e-12) return Eigen::Vector3d::Zero();
  return frame.transpose() * (robot.strut_radius_m * d.normalized());
}

}  // namespace tensegrity::sim
