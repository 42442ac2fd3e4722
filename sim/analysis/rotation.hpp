// SPDX-License-Identifier: Apache-2.0
#pragma once
// How far the robot turned: the best-fit rotation of its end caps from one sample to
// the next (Kabsch), accumulated. A rolling robot turns 2 pi per revolution about a
// horizontal axis, whatever its cables do to its shape.
#include <Eigen/Core>
#include <vector>

namespace tensegrity::sim::analysis {

// The rotation that best maps the centred points `from` onto the centred `to`
// (least squares, proper: det = +1).
Eigen::Matrix3d best_rotation(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to);

struct Turning {
  // Sum of the per-sample rotation vectors (axis x angle) from `first` on, rad: its
  // length is the net angle rolled about a steady axis.
  Eigen::Vector3d rotation_rad = Eigen::Vector3d::Zero();
  double net_angle_rad = 0.0;    // |rotation_rad|
  double total_angle_rad = 0.0;  // sum of |per-sample angle|: rocking counts too
  double revolutions() const;    // net angle / 2 pi
};
Turning accumulate_turning(const std::vector<std::vector<Eigen::Vector3d>>& node_m, std::size_t first);

}  // namespace tensegrity::sim::analysis
