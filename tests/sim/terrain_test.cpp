// SPDX-License-Identifier: Apache-2.0
// Ground that is not a plane: a body on a slope holds or slides as tan(slope) against
// the friction coefficient says, in both engines; a body dropped on rough ground comes
// to rest on the bumps' heights; a seeded ground is the same to the bit every time.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "sim/model/episode.hpp"
#include "sim/model/model.hpp"
#include "sim/model/terrain.hpp"

namespace tensegrity::sim {
namespace {

constexpr double kRadius = 0.0175;

// Two struts of `length` lying side by side along x, 2 m apart, joined by one slack
// cable: lying along the fall line (the slope falls toward +x), they cannot roll, only
// slide. With friction `mu` and, on rough ground, bumps every `length` metres.
Robot pair_of_struts(double length, double mu, Robot::PhysicsEngine engine) {
  const std::string l = std::to_string(length);
  const std::string text = R"({
    "format": "tensegrity-robot/1", "name": "pair", "gravity_m_per_s2": 9.81, "time_step_s": 0.001,
    "nodes_m": [[0, 0, 0], [)" +
                           l + R"(, 0, 0], [0, 2, 0], [)" + l + R"(, 2, 0]],
    "strut": {"mass_kg": 3.5, "radius_m": 0.0175},
    "struts": [[0, 1], [2, 3]],
    "cable": {"stiffness_n_per_m": 1000, "damping_n_s_per_m": 50, "initial_rest_length_m": 2.9,
              "min_rest_length_m": 0.6, "max_rest_length_m": 3.0, "motor_speed_m_per_s": 0.2,
              "cutoff_tension_n": 400, "hard_limit_tension_n": 500},
    "cables": [{"nodes": [0, 2], "owner": 0}],
    "ground": {"friction": )" +
                           std::to_string(mu) +
                           R"(, "contact_stiffness_n_per_m": 500000, "contact_damping_n_s_per_m": 2000},
    "start": {"clearance_m": 0.0, "settle_s": 0}
  })";
  Robot robot = parse_robot(text, "pair.json");
  robot.engine = engine;
  return robot;
}

// How far the pair moves along the slope in `seconds`, after 0.2 s to come to rest.
double slide_m(Robot robot, double slope_deg, double seconds) {
  robot.ground_slope_deg = slope_deg;
  Model model(robot, robot.time_step_s);
  std::vector<Eigen::Vector3d> nodes = robot.nodes_m;
  for (auto& p : nodes) p.z() = kRadius;
  model.place(nodes);
  const std::vector<double> hold(1, robot.initial_rest_length_m);
  for (int i = 0; i < 200; ++i) model.step(hold);
  const double x0 = model.centre_m().x();
  const auto steps = static_cast<int>(std::lround(seconds / robot.time_step_s));
  for (int i = 0; i < steps; ++i) model.step(hold);
  EXPECT_TRUE(model.state_finite());
  return model.centre_m().x() - x0;
}

double friction_angle_deg(double mu) { return std::atan(mu) * 180.0 / std::numbers::pi; }

// Sliding from rest at contact, the pair accelerates at g (sin a - mu cos a) down the
// slope (+x): from 0.2 s to 2.2 s it covers half that times (2.2^2 - 0.2^2).
double coulomb_slide_m(double slope_deg, double mu) {
  const double a = slope_deg * std::numbers::pi / 180.0;
  return 0.5 * 9.81 * (std::sin(a) - mu * std::cos(a)) * (2.2 * 2.2 - 0.2 * 0.2);
}

TEST(Slope, HoldsBelowTheFrictionAngleAndSlidesAboveAsCoulombSays) {
  const double mu = 0.5;
  const Robot robot = pair_of_struts(1.0, mu, Robot::PhysicsEngine::ode);
  const double below = friction_angle_deg(mu) - 1.0;
  const double above = friction_angle_deg(mu) + 1.0;
  EXPECT_LT(std::abs(slide_m(robot, below, 2.0)), 1e-4) << "slid at " << below << " deg";
  const double slid = slide_m(robot, above, 2.0);
  EXPECT_GT(slid, 0.0);
  EXPECT_NEAR(slid, coulomb_slide_m(above, mu), 0.05 * coulomb_slide_m(above, mu));
}

TEST(Slope, TheBulletEngineHoldsAndSlidesToo) {
  const double mu = 0.5;
  const Robot robot = pair_of_struts(1.0, mu, Robot::PhysicsEngine::bullet);
  EXPECT_LT(std::abs(slide_m(robot, friction_angle_deg(mu) - 5.0, 2.0)), 0.01);
  const double above = friction_angle_deg(mu) + 5.0;
  EXPECT_NEAR(slide_m(robot, above, 2.0), coulomb_slide_m(above, mu), 0.05 * coulomb_slide_m(above, mu));
}

TEST(Slope, LevelGroundKeepsGravityStraightDown) {
  Robot robot = pair_of_struts(1.0, 1.0, Robot::PhysicsEngine::ode);
  robot.ground_slope_azimuth_deg = 135.0;  // no slope: the azimuth means nothing
  const Eigen::Vector3d g = Terrain(robot).gravity_m_per_s2(9.81);
  EXPECT_EQ(g, Eigen::Vector3d(0.0, 0.0, -9.81));
  robot.ground_slope_deg = 10.0;
  robot.ground_slope_azimuth_deg = 90.0;
  const Eigen::Vector3d tilted = Terrain(robot).gravity_m_per_s2(9.81);
  EXPECT_NEAR(tilted.norm(), 9.81, 1e-12);
  EXPECT_NEAR(tilted.y(), 9.81 * std::sin(10.0 * std::numbers::pi / 180.0), 1e-12);
  EXPECT_NEAR(tilted.x(), 0.0, 1e-12);
}

Robot on_bumps(double spacing, std::uint64_t seed) {
  Robot robot = pair_of_struts(spacing, 1.0, Robot::PhysicsEngine::ode);
  robot.ground_rough = {0.05, spacing, seed};
  return robot;
}

TEST(RoughGround, ABodyDroppedOnBumpsRestsAtTheirHeights) {
  // The struts are one bump spacing long: each end cap lands on a grid node, the top
  // of a bump or the bottom of a dip, where the ground is level.
  const Robot robot = on_bumps(1.0, 3);
  const Terrain terrain(robot);
  Model model(robot, robot.time_step_s);
  std::vector<Eigen::Vector3d> nodes = robot.nodes_m;
  for (auto& p : nodes) p.z() = terrain.max_height_m() + kRadius + 0.02;
  model.place(nodes);
  const std::vector<double> hold(1, robot.initial_rest_length_m);
  for (int i = 0; i < 1500; ++i) model.step(hold);
  ASSERT_TRUE(model.state_finite());
  double spread = 0.0;
  for (int node = 0; node < 4; ++node) {
    const Eigen::Vector3d p = model.node_position(node);
    const Eigen::Vector3d& at = robot.nodes_m[node];
    const double ground = terrain.node_height_m(std::lround(at.x()), std::lround(at.y() / 1.0));
    EXPECT_NEAR(p.z(), ground + kRadius, 5e-4) << "end cap " << node;
    EXPECT_NEAR(p.x(), at.x(), 3e-3) << "end cap " << node << " slid off its node";
    spread = std::max(spread, std::abs(ground - terrain.node_height_m(0, 0)));
  }
  EXPECT_GT(spread, 0.005) << "the bumps are all alike: the test would not see heights";
  EXPECT_EQ(model.ground_contact_mask(), 0xFU);
}

TEST(RoughGround, IsSmoothAndWithinItsHeight) {
  const Terrain terrain(on_bumps(0.5, 11));
  for (double x = -3.0; x < 3.0; x += 0.0137) {
    const double y = 0.7 * x + 0.3;
    const double h = terrain.height_m(x, y);
    EXPECT_GE(h, 0.0);
    EXPECT_LT(h, 0.05);
    // The gradient is the height's derivative (central difference).
    const double e = 1e-6;
    const Eigen::Vector2d g = terrain.gradient(x, y);
    EXPECT_NEAR(g.x(), (terrain.height_m(x + e, y) - terrain.height_m(x - e, y)) / (2 * e), 1e-6);
    EXPECT_NEAR(g.y(), (terrain.height_m(x, y + e) - terrain.height_m(x, y - e)) / (2 * e), 1e-6);
  }
}

TEST(RoughGround, FarOrNonFinitePositionsAreLevel) {
  const Terrain terrain(on_bumps(0.5, 11));
  EXPECT_EQ(terrain.height_m(1e300, 0.0), 0.0);
  EXPECT_EQ(terrain.height_m(0.0, std::nan("")), 0.0);
  EXPECT_EQ(terrain.gradient(-1e300, 1.0), Eigen::Vector2d::Zero());
}

// A short episode of the paper's robot on bumps, from the drop start.
ModelState rolled_on(const Robot& robot) {
  ConstantController hold(robot.initial_rest_length_m - 0.1);
  EpisodeOptions options;
  options.duration_s = 1.5;
  options.start = StartKind::drop;
  ModelState end;
  options.end_state = &end;
  run_episode(robot, hold, options);
  return end;
}

TEST(RoughGround, ASeededGroundIsTheSameToTheBit) {
  Robot robot = load_robot(robot_path_named("superball-paper"));
  robot.ground_rough = {0.05, 0.5, 42};
  robot.hash += "-rough42";
  const Terrain a(robot);
  const Terrain b(robot);
  for (int i = -50; i < 50; ++i) ASSERT_EQ(a.node_height_m(i, 3 * i), b.node_height_m(i, 3 * i));
  const ModelState first = rolled_on(robot);
  const ModelState second = rolled_on(robot);
  EXPECT_EQ(first.body, second.body);
  Robot other = robot;
  other.ground_rough.seed = 43;
  other.hash += "-rough43";
  EXPECT_NE(Terrain(other).node_height_m(0, 0), a.node_height_m(0, 0));
  EXPECT_NE(rolled_on(other).body, first.body) << "the seed changed nothing";
}

}  // namespace
}  // namespace tensegrity::sim
