// SPDX-License-Identifier: Apache-2.0
#include "ground/drive/face_geometry.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace tensegrity::drive {
FaceGeometry::FaceGeometry(const sim::Robot& robot) : faces_(sim::hull_faces(robot)) {
  const int n = robot.node_count();
  axis_.assign(n, Eigen::Vector3d::UnitZ());
  for (const auto& s : robot.struts) {
    const Eigen::Vector3d u = (robot.nodes_m[s.node_a] - robot.nodes_m[s.node_b]).normalized();
    axis_[s.node_a] = u;
    axis_[s.node_b] = -u;
  }
  // reading_i = g * axis_i . up = -g * axis_i . down: least squares for down.
  Eigen::Matrix<double, Eigen::Dynamic, 3> u(n, 3);
  for (int i = 0; i < n; ++i) u.row(i) = axis_[i].transpose();
  const Eigen::Matrix3d normal = u.transpose() * u;
  fit_ = normal.fullPivLu().isInvertible() ? Eigen::Matrix<double, 3, Eigen::Dynamic>(normal.inverse() * u.transpose())
                                           : Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, n);
}

int FaceGeometry::face_index(std::array<int, 3> nodes) const {
  std::sort(nodes.begin(), nodes.end());
  for (std::size_t i = 0; i < faces_.size(); ++i) {
    if (faces_[i].nodes == nodes) return static_cast<int>(i);
  }
  return -1;
}

std::optional<Eigen::Vector3d> FaceGeometry::down(std::span<const Eigen::Vector3d> readings) const {
  if (static_cast<int>(readings.size()) != endcap_count()) return std::nullopt;
  Eigen::VectorXd axial(readings.size());
  for (std::size_t i = 0; i < readings.size(); ++i) axial[static_cast<Eigen::Index>(i)] = readings[i].z();
  // A robot at rest feels gravity alone: each end cap reads g in all, and the fit is
  // a unit vector. Falling or hitting the ground it feels far more or less; the
  // reading then tells its motion more than its pose, and is left out.
  double magnitude = 0.0;
  for (const auto& r : readings) magnitude += r.norm() / static_cast<double>(readings.size());
  const Eigen::Vector3d d = -(fit_ * axial) / kGravity_m_per_s2;
  if (!d.allFinite() || std::abs(d.norm() - 1.0) > 0.5 || std::abs(magnitude - kGravity_m_per_s2) > 5.0) {
    return std::nullopt;
  }
  return d.normalized();
}

int FaceGeometry::nearest_face(const Eigen::Vector3d& down) const {
  int best = -1;
  double best_dot = -2.0;
  for (std::size_t i = 0; i < faces_.size(); ++i) {
    const double d = faces_[i].normal.dot(down);
    if (d > best_dot) {
      best_dot = d;
      best = static_cast<int>(i);
    }
  }
  return best;
}

}  // namespace tensegrity::drive
