// SPDX-License-Identifier: Apache-2.0
// The estimator on synthetic data with known truth: the face from noisy accelerometer
// readings, the yaw turned at each tip, position and velocity from noisy fixes.
#include "ground/drive/estimator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "ground/drive/steering.hpp"
#include "robot/start_frame.hpp"
#include "synthetic.hpp"

namespace tensegrity::drive {
namespace {

using testing::pose;
using testing::readings;

class EstimatorTest : public ::testing::Test {
 protected:
  sim::Robot robot = sim::load_robot(sim::default_robot_path());
  FaceGeometry geometry{robot};
  std::mt19937_64 random{7};
};

TEST_F(EstimatorTest, EveryFaceIsToldFromNoisyReadingsAtAnyYaw) {
  ASSERT_EQ(geometry.faces().size(), 20u);
  for (std::size_t f = 0; f < geometry.faces().size(); ++f) {
    for (double yaw : {-2.5, -1.0, 0.0, 0.7, 3.0}) {
      // 0.3 m/s^2 per axis, as the model's emulated sensors add.
      const auto r = readings(robot, pose(geometry.faces(), static_cast<int>(f), yaw), 0.3, random);
      const auto down = geometry.down(r);
      ASSERT_TRUE(down.has_value());
      EXPECT_EQ(geometry.nearest_face(*down), static_cast<int>(f)) << "face " << f << " yaw " << yaw;
      EXPECT_GT(down->dot(geometry.faces()[f].normal), 0.99);
    }
  }
}

TEST_F(EstimatorTest, NoFaceInFreeFall) {
  const std::vector<Eigen::Vector3d> weightless(robot.node_count(), Eigen::Vector3d::Zero());
  EXPECT_FALSE(geometry.down(weightless).has_value());
  EXPECT_FALSE(geometry.down(std::vector<Eigen::Vector3d>(3, Eigen::Vector3d::UnitZ())).has_value());
}

TEST_F(EstimatorTest, FollowsTheFaceAndTheYawThroughARoll) {
  const auto& faces = geometry.faces();
  EstimatorConfig config;
  config.initial_yaw_rad = 0.3;
  Estimator estimator(geometry, config);
  // Roll a rigid robot over three edges, reading at 20 Hz for a second on each face.
  int face = 0, previous = -1;
  double yaw = 0.3;
  double t = 0.0;
  for (int roll = 0; roll < 4; ++roll) {
    for (int k = 0; k < 20; ++k, t += 0.05) {
      estimator.add_accelerations(t, readings(robot, pose(faces, face, yaw), 0.3, random));
    }
    const Estimate e = estimator.estimate(t);
    EXPECT_EQ(e.face, face);
    // Each reading's down direction is off by about 0.3 / 9.81 / sqrt(12) rad of noise
    // (0.5 degrees); the shortest rotations that follow it jitter the yaw by a fraction
    // of that. The tips themselves turn the yaw by tens of degrees.
    EXPECT_NEAR(wrap_rad(e.yaw_rad - yaw) * 180.0 / std::numbers::pi, 0.0, 2.0) << "roll " << roll;
    // The next face: one sharing an edge with this one.
    int next = -1;
    for (std::size_t b = 0; b < faces.size() && next < 0; ++b) {
      int shared = 0;
      for (int i : faces[face].nodes)
        shared += static_cast<int>(std::count(faces[b].nodes.begin(), faces[b].nodes.end(), i));
      if (shared == 2 && static_cast<int>(b) != previous) next = static_cast<int>(b);
    }
    const Eigen::Matrix3d before = pose(faces, face, yaw);
    const Eigen::Matrix3d tipped =
        Eigen::Quaterniond::FromTwoVectors(before * faces[next].normal, -Eigen::Vector3d::UnitZ()) * before;
    const Eigen::Matrix3d yawed = tipped * sim::face_down_turn(faces[next].normal).transpose();
    yaw = std::atan2(yawed(1, 0), yawed(0, 0));
    previous = face;
    face = next;
  }
  EXPECT_EQ(estimator.face_changes(), 3);
}

TEST_F(EstimatorTest, PositionAndVelocityFromNoisyFixes) {
  Estimator estimator(geometry, {});
  std::normal_distribution<double> noise(0.0, 0.1);
  const Eigen::Vector2d v(0.4, -0.3);  // m/s
  double worst_m = 0.0;
  for (int k = 0; k <= 60; ++k) {
    const double t = k;  // 1 Hz
    estimator.add_fix(t, v * t + Eigen::Vector2d(noise(random), noise(random)));
    if (k < 3) continue;
    const Estimate e = estimator.estimate(t + 0.5);
    worst_m = std::max(worst_m, (e.position_m - v * (t + 0.5)).norm());
    EXPECT_LT((e.velocity_m_per_s - v).norm(), 0.25);
  }
  // 0.1 m per axis per fix, averaged over a 3 s window: never as far off as 0.4 m.
  EXPECT_LT(worst_m, 0.4);
  EXPECT_GT(worst_m, 0.0);
}

}  // namespace
}  // namespace tensegrity::drive
