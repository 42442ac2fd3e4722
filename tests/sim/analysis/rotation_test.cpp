// SPDX-License-Identifier: Apache-2.0
// Revolutions counted from end-cap positions alone.
#include "sim/analysis/rotation.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numbers>

namespace tensegrity::sim::analysis {
namespace {

std::vector<Eigen::Vector3d> body() {
  return {{0.3, 0.1, 0.0}, {-0.2, 0.4, 0.1}, {0.0, -0.5, 0.3}, {0.1, 0.2, -0.6}, {-0.4, -0.1, 0.2}};
}

TEST(Rotation, BestRotationRecoversAKnownTurn) {
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  std::vector<Eigen::Vector3d> to;
  for (const auto& p : body()) to.push_back(r * p + Eigen::Vector3d(5, -1, 2));
  EXPECT_LT((best_rotation(body(), to) - r).norm(), 1e-9);
}

TEST(Rotation, CountsRevolutionsOfARollAndNotOfARock) {
  // 2.5 turns about the y axis while moving along x, in 0.05 rad steps.
  std::vector<std::vector<Eigen::Vector3d>> roll, rock;
  const double total = 2.5 * 2.0 * std::numbers::pi;
  for (int k = 0; k <= 315; ++k) {
    const double angle = total * k / 315.0;
    const Eigen::AngleAxisd r(angle, Eigen::Vector3d::UnitY());
    const Eigen::AngleAxisd back(0.4 * std::sin(0.2 * k), Eigen::Vector3d::UnitY());
    std::vector<Eigen::Vector3d> a, b;
    for (const auto& p : body()) {
      a.push_back(r * p + Eigen::Vector3d(0.5 * angle, 0, 0));
      b.push_back(back * p);
    }
    roll.push_back(a);
    rock.push_back(b);
  }
  const Turning t = accumulate_turning(roll, 0);
  EXPECT_NEAR(t.revolutions(), 2.5, 1e-6);
  EXPECT_NEAR(t.rotation_rad.normalized().y(), 1.0, 1e-9);
  const Turning r = accumulate_turning(rock, 0);
  EXPECT_LT(r.revolutions(), 0.07);
  EXPECT_GT(r.total_angle_rad, 2.0 * std::numbers::pi);  // it did move, back and forth
}

}  // namespace
}  // namespace tensegrity::sim::analysis
