// SPDX-License-Identifier: Apache-2.0
#include "sim/analysis/rotation.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <numbers>

namespace tensegrity::sim::analysis {
namespace {

Eigen::Vector3d centroid(const std::vector<Eigen::Vector3d>& p) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& x : p) c += x;
  return c / static_cast<double>(p.size());
}

}  // namespace

Eigen::Matrix3d best_rotation(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to) {
  const Eigen::Vector3d cf = centroid(from), ct = centroid(to);
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) h += (from[i] - cf) * (to[i] - ct).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  // A reflection fits as well when the points are flat; never return one.
  if ((svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0) d(2, 2) = -1.0;
  return svd.matrixV() * d * svd.matrixU().transpose();
}

double Turning::revolutions() const { return net_angle_rad / (2.0 * std::numbers::pi); }

Turning accumulate_turning(const std::vector<std::vector<Eigen::Vector3d>>& node_m, std::size_t first) {
  Turning t;
  for (std::size_t k = first + 1; k < node_m.size(); ++k) {
    const Eigen::AngleAxisd step(best_rotation(node_m[k - 1], node_m[k]));
    t.rotation_rad += step.angle() * step.axis();
    t.total_angle_rad += std::abs(step.angle());
  }
  t.net_angle_rad = t.rotation_rad.norm();
  return t;
}

}  // namespace tensegrity::sim::analysis
