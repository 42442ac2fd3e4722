// SPDX-License-Identifier: Apache-2.0
#include "sim/model/terrain.hpp"

#include <cmath>
#include <numbers>

namespace tensegrity::sim {
namespace {

// SplitMix64's finaliser: a well-mixed 64-bit hash of its input, the same on every
// platform (integers only), so a seed names one ground everywhere.
std::uint64_t mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Smoothstep and its derivative: heights blend between grid nodes with zero slope at
// every node, so the surface is smooth (C1) and each node is a bump's top or a dip's bottom.
double smooth(double t) { return t * t * (3.0 - 2.0 * t); }
double smooth_slope(double t) { return 6.0 * t * (1.0 - t); }

double radians(double deg) { return deg * std::numbers::pi / 180.0; }

// Grid indices are 64-bit integers: beyond this (or at NaN) a position has diverged,
// and converting it would be undefined. The ground there is taken as level at 0.
constexpr double kFarM = 1e12;
bool on_the_grid(double x, double y) { return std::abs(x) < kFarM && std::abs(y) < kFarM; }

}  // namespace

Terrain::Terrain(const Robot& robot)
    : slope_rad_(radians(robot.ground_slope_deg)),
      azimuth_rad_(radians(robot.ground_slope_azimuth_deg)),
      bump_height_m_(robot.ground_rough.bump_height_m),
      spacing_m_(robot.ground_rough.bump_spacing_m),
      seed_(robot.ground_rough.seed) {}

Eigen::Vector3d Terrain::gravity_m_per_s2(double g) const {
  // Level ground keeps the literal (0, 0, -g): results stay bit for bit.
  if (slope_rad_ == 0.0) return {0.0, 0.0, -g};
  const double along = g * std::sin(slope_rad_);
  return {along * std::cos(azimuth_rad_), along * std::sin(azimuth_rad_), -g * std::cos(slope_rad_)};
}

double Terrain::node_height_m(std::int64_t i, std::int64_t j) const {
  const std::uint64_t h = mix(mix(mix(seed_) ^ static_cast<std::uint64_t>(i)) ^ static_cast<std::uint64_t>(j));
  // The top 53 bits as a fraction in [0, 1): exact in a double.
  return bump_height_m_ * static_cast<double>(h >> 11) * 0x1.0p-53;
}

double Terrain::height_m(double x, double y) const {
  if (!rough() || !on_the_grid(x, y)) return 0.0;
  const double gx = std::floor(x / spacing_m_);
  const double gy = std::floor(y / spacing_m_);
  const auto i = static_cast<std::int64_t>(gx);
  const auto j = static_cast<std::int64_t>(gy);
  const double sx = smooth(x / spacing_m_ - gx);
  const double sy = smooth(y / spacing_m_ - gy);
  const double low = node_height_m(i, j) + sx * (node_height_m(i + 1, j) - node_height_m(i, j));
  const double high = node_height_m(i, j + 1) + sx * (node_height_m(i + 1, j + 1) - node_height_m(i, j + 1));
  return low + sy * (high - low);
}

Eigen::Vector2d Terrain::gradient(double x, double y) const {
  if (!rough() || !on_the_grid(x, y)) return Eigen::Vector2d::Zero();
  const double gx = std::floor(x / spacing_m_);
  const double gy = std::floor(y / spacing_m_);
  const auto i = static_cast<std::int64_t>(gx);
  const auto j = static_cast<std::int64_t>(gy);
  const double tx = x / spacing_m_ - gx;
  const double ty = y / spacing_m_ - gy;
  const double h00 = node_height_m(i, j);
  const double h10 = node_height_m(i + 1, j);
  const double h01 = node_height_m(i, j + 1);
  const double h11 = node_height_m(i + 1, j + 1);
  const double sx = smooth(tx);
  const double sy = smooth(ty);
  const double dx = smooth_slope(tx) / spacing_m_ * ((h10 - h00) + sy * ((h11 - h01) - (h10 - h00)));
  const double dy = smooth_slope(ty) / spacing_m_ * ((h01 - h00) + sx * ((h11 - h01) - (h10 - h00)));
  return {dx, dy};
}

bool Terrain::touches(const Eigen::Vector3d& c, double radius_m, GroundContact& contact) const {
  if (!rough()) {
    // The plane z = 0, computed as the model always has.
    const double depth = radius_m - c.z();
    if (depth <= 0.0) return false;
    contact.point_m = {c.x(), c.y(), c.z() - radius_m};
    contact.normal = Eigen::Vector3d::UnitZ();
    contact.depth_m = depth;
    return true;
  }
  const double h = height_m(c.x(), c.y());
  // Cheap rejection: no bump reaches above the field's top.
  if (c.z() - radius_m >= bump_height_m_) return false;
  const Eigen::Vector2d g = gradient(c.x(), c.y());
  const Eigen::Vector3d n = Eigen::Vector3d(-g.x(), -g.y(), 1.0).normalized();
  // Distance from the centre to the tangent plane through (x, y, h).
  const double depth = radius_m - (c.z() - h) * n.z();
  if (depth <= 0.0) return false;
  contact.point_m = c - radius_m * n;
  contact.normal = n;
  contact.depth_m = depth;
  return true;
}

}  // namespace tensegrity::sim
