// SPDX-License-Identifier: Apache-2.0
#pragma once
// The ground under the robot, as the robot file's `ground` describes it: the plane
// z = 0, optionally tilted (a slope) and optionally rough (seeded bumps). A slope is
// modelled by tilting gravity, not the plane: the ground stays at z = 0, so x and y
// run along the slope and every distance is measured on it. Bumps are a height
// field h(x, y) >= 0 over the whole plane, a pure function of the seed (no state, no
// table: reproducible to the bit in any thread, with no edge to roll off).
#include <Eigen/Core>
#include <cstdint>

#include "robot/robot.hpp"

namespace tensegrity::sim {

// Where a sphere meets the ground: the contact point on the ground, the ground's
// outward normal there, and how deep the sphere reaches into it.
struct GroundContact {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double depth_m = 0.0;
};

class Terrain {
 public:
  explicit Terrain(const Robot& robot);

  // Gravity in the ground's frame, m/s^2: (0, 0, -g) on level ground, exactly.
  Eigen::Vector3d gravity_m_per_s2(double g_m_per_s2) const;
  bool rough() const { return bump_height_m_ > 0.0; }
  // The highest the ground reaches: a start above it meets no bump.
  double max_height_m() const { return bump_height_m_; }
  // The ground's height at (x, y) and its gradient (dh/dx, dh/dy).
  double height_m(double x_m, double y_m) const;
  Eigen::Vector2d gradient(double x_m, double y_m) const;
  // Whether a sphere of `radius_m` centred at `centre_m` touches the ground, and where.
  // On rough ground the ground under the centre is taken as its tangent plane there,
  // which is exact on flat ground and close while the bumps' curvature radius is
  // well above the sphere's (robot.cpp bounds the bumps' steepness).
  bool touches(const Eigen::Vector3d& centre_m, double radius_m, GroundContact& contact) const;
  // Height of grid node (i, j), in [0, bump_height_m): a hash of the seed and the indices.
  double node_height_m(std::int64_t i, std::int64_t j) const;

 private:
  double slope_rad_;
  double azimuth_rad_;
  double bump_height_m_;
  double spacing_m_;
  std::uint64_t seed_;
};

}  // namespace tensegrity::sim
