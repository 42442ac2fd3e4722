// SPDX-License-Identifier: Apache-2.0
// The gait choice: the gait pointing nearest the waypoint, kept unless another gains
// the margin, the yaw corrected by the measured path, bands alternated to reach a
// heading between them, and waypoints taken in order. A kinematic robot stands in
// for the model: each period it rolls 2.2 m in its gait's true heading.
#include "ground/drive/steering.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "synthetic.hpp"

namespace tensegrity::drive {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

class SteeringTest : public ::testing::Test {
 public:
  void SetUp() override {
    // Three gaits from face 0, 120 degrees apart in its start frame.
    const auto nodes = geometry.faces()[face].nodes;
    set.robot = robot.name;
    for (double h : {0.0, 120.0, -120.0}) {
      sim::Gait g;
      g.name = "h" + std::to_string(static_cast<int>(h));
      g.face = nodes;
      g.heading_deg = h;
      set.gaits.push_back(g);
    }
  }

  // The estimator as it stands at rest on `face` at `yaw_rad`, at `at_m`.
  void stand(Estimator& estimator, double t, const Eigen::Vector2d& at_m, double yaw_rad) {
    for (int k = 0; k < 10; ++k) {
      estimator.add_accelerations(
          t - 0.5 + 0.05 * k, testing::readings(robot, testing::pose(geometry.faces(), face, yaw_rad), 0.3, random));
    }
    estimator.add_fix(t - 1.0, at_m);
    estimator.add_fix(t, at_m);
  }

  sim::Robot robot = sim::load_robot(sim::default_robot_path());
  FaceGeometry geometry{robot};
  int face = 0;
  sim::GaitSet set;
  std::mt19937_64 random{3};
};

TEST_F(SteeringTest, ChoosesTheGaitPointingNearestTheWaypoint) {
  for (double bearing_deg : {10.0, 100.0, -100.0, 170.0}) {
    EstimatorConfig ec;
    ec.initial_yaw_rad = 30.0 * kDeg;  // world heading = 30 + the gait's
    Estimator estimator(geometry, ec);
    stand(estimator, 0.0, Eigen::Vector2d::Zero(), ec.initial_yaw_rad);
    const Eigen::Vector2d goal = 20.0 * Eigen::Vector2d(std::cos(bearing_deg * kDeg), std::sin(bearing_deg * kDeg));
    Steering steering(set, geometry, {goal}, {});
    const Choice c = steering.choose(0.0, estimator);
    ASSERT_GE(c.gait, 0);
    double best = 1e9;
    int want = -1;
    for (int g = 0; g < 3; ++g) {
      const double e = std::abs(wrap_rad((30.0 + set.gaits[g].heading_deg - bearing_deg) * kDeg));
      if (e < best) best = e, want = g;
    }
    EXPECT_EQ(c.gait, want) << "bearing " << bearing_deg;
    EXPECT_TRUE(c.switched);
    EXPECT_NEAR(c.bearing_rad, bearing_deg * kDeg, 1e-9);
  }
}

// Rolls a kinematic robot: each period 2.2 m along its gait's true heading, which is
// off the gait set's by `bias_deg` (the model's ground is not isotropic).
struct Kinematic {
  Eigen::Vector2d at = Eigen::Vector2d::Zero();
  int switches = 0;
  int periods = 0;
};

Kinematic roll(SteeringTest& test, Steering& steering, Estimator& estimator, double yaw_rad, double bias_deg,
               int max_periods) {
  Kinematic k;
  std::normal_distribution<double> fix_noise(0.0, 0.1);
  int gait = -1;
  double t = 0.0;
  for (; k.periods < max_periods && !steering.done(); ++k.periods) {
    const Choice c = steering.choose(t, estimator);
    if (c.switched && gait >= 0) ++k.switches;
    gait = c.gait;
    const double h = yaw_rad + (test.set.gaits[gait].heading_deg + bias_deg) * kDeg;
    const Eigen::Vector2d step = 2.2 / 4.0 * Eigen::Vector2d(std::cos(h), std::sin(h));
    for (int s = 0; s < 4; ++s) {  // 1 Hz fixes over a 4 s period
      t += 1.0;
      k.at += step;
      estimator.add_fix(t, k.at + Eigen::Vector2d(fix_noise(test.random), fix_noise(test.random)));
      steering.update(estimator.estimate(t));
    }
  }
  return k;
}

TEST_F(SteeringTest, AlternatesBandsToReachAHeadingBetweenThem) {
  Estimator estimator(geometry, {});
  stand(estimator, 0.0, Eigen::Vector2d::Zero(), 0.0);
  // 60 degrees: halfway between the gaits at 0 and 120.
  const Eigen::Vector2d goal = 20.0 * Eigen::Vector2d(std::cos(60.0 * kDeg), std::sin(60.0 * kDeg));
  Steering steering(set, geometry, {goal}, {});
  const Kinematic k = roll(*this, steering, estimator, 0.0, 0.0, 40);
  EXPECT_TRUE(steering.done());
  EXPECT_GE(k.switches, 3);  // one band alone would pass 10 m wide of the goal
}

TEST_F(SteeringTest, CorrectsTheYawByTheMeasuredPath) {
  Estimator estimator(geometry, {});
  stand(estimator, 0.0, Eigen::Vector2d::Zero(), 0.0);
  // Goal along the first gait's heading; the gait truly rolls 20 degrees to the left.
  Steering steering(set, geometry, {Eigen::Vector2d(20.0, 0.0)}, {});
  roll(*this, steering, estimator, 0.0, 20.0, 2);
  steering.choose(8.0, estimator);  // the third boundary sees the first gait's path
  // Half (yaw_gain) the measured 20 degrees, within what 0.1 m fixes allow over 4.4 m.
  EXPECT_NEAR(estimator.estimate(8.0).yaw_rad / kDeg, 10.0, 3.0);
}

TEST_F(SteeringTest, ReachesWaypointsInOrderDespiteABiasedGait) {
  Estimator estimator(geometry, {});
  stand(estimator, 0.0, Eigen::Vector2d::Zero(), 0.0);
  const std::vector<Eigen::Vector2d> course{{10.0, 0.0}, {10.0, 10.0}, {0.0, 10.0}, {0.0, 0.0}};
  Steering steering(set, geometry, course, {});
  const Kinematic k = roll(*this, steering, estimator, 0.0, 15.0, 200);
  EXPECT_TRUE(steering.done());
  EXPECT_EQ(steering.active(), course.size());
  EXPECT_LT((k.at - course.back()).norm(), 1.5 + 0.5);  // reached, then at most one fix interval on
}

TEST_F(SteeringTest, NoChoiceWithoutAFaceOrAFix) {
  Estimator estimator(geometry, {});
  Steering steering(set, geometry, {Eigen::Vector2d(5.0, 0.0)}, {});
  EXPECT_EQ(steering.choose(0.0, estimator).gait, -1);
  estimator.add_fix(0.0, Eigen::Vector2d::Zero());
  EXPECT_EQ(steering.choose(0.0, estimator).gait, -1);  // still no face
}

}  // namespace
}  // namespace tensegrity::drive
