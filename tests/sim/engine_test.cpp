// SPDX-License-Identifier: Apache-2.0
// The Bullet engine against the ODE one: the same robot must stand, keep its energy
// and collide in both, so that a difference in learning is the engines' contacts
// and integration, not a broken model. And the zeroed axial spin of the NTRT
// Bullet cross-check, in both engines.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "sim/model/episode.hpp"
#include "sim/model/model.hpp"
#include "tests/sim/crossing_struts.hpp"

namespace tensegrity::sim {
namespace {

// settled_state() caches by hash and name: a robot changed in code needs its own.
Robot with_engine(Robot robot, Robot::PhysicsEngine engine) {
  robot.engine = engine;
  if (engine == Robot::PhysicsEngine::bullet) robot.hash += "-bullet";
  return robot;
}

Robot superball(Robot::PhysicsEngine engine) { return with_engine(load_robot(robot_path_named("superball")), engine); }

void run(Model& model, double seconds, std::span<const double> preferred) {
  const auto steps = static_cast<int>(std::lround(seconds / model.dt_s()));
  for (int i = 0; i < steps; ++i) model.step(preferred);
}

double mean(std::span<const double> values) {
  double sum = 0.0;
  for (const double v : values) sum += v;
  return sum / static_cast<double>(values.size());
}

TEST(BulletEngine, StandsOnThreeEndCapsWithOdesTensions) {
  const Robot ode = superball(Robot::PhysicsEngine::ode);
  const Robot bullet = superball(Robot::PhysicsEngine::bullet);
  Model model(bullet, bullet.time_step_s);
  model.restore(settled_state(bullet, bullet.time_step_s));
  const std::vector<double> hold(24, bullet.initial_rest_length_m);
  model.step(hold);
  const Eigen::Vector3d start = model.centre_m();
  run(model, 20.0, hold);
  ASSERT_TRUE(model.state_finite());
  EXPECT_LT((model.centre_m() - start).norm(), 0.01) << "the settled robot drifted";
  // Bullet's resting contacts do not hold the tripod quite still: it turns in place
  // at about 0.03 rad/s (6 mJ), with or without spin, gyroscopic term, 50 solver
  // iterations or two friction directions (docs/design/model.md, "Engines"). The centre stays.
  EXPECT_LT(model.kinetic_energy_j(), 0.02);
  EXPECT_EQ(std::popcount(model.ground_contact_mask()), 3) << "not on a triangle of end caps";
  EXPECT_GE(model.contact_count(), 3);
  const double ode_mean = mean(settled_state(ode, ode.time_step_s).tension_n);
  const double bullet_mean = mean(model.tension_n());
  std::printf("settled mean tension: ODE %.2f N, Bullet %.2f N\n", ode_mean, bullet_mean);
  // The same cables on the same rigid struts: the engines may differ in how deep
  // an end cap sits in the ground, not in the structure's prestress.
  EXPECT_NEAR(bullet_mean, ode_mean, 0.02 * ode_mean);
}

TEST(BulletEngine, KeepsEnergyWithoutGravityGroundAndDamping) {
  const Robot robot = superball(Robot::PhysicsEngine::bullet);
  Model model(robot, robot.time_step_s);
  model.set_gravity_enabled(false);
  model.set_ground_enabled(false);
  model.set_damping_enabled(false);
  for (int s = 0; s < 6; ++s) {
    model.set_velocity(s, Eigen::Vector3d(0.1 * s, -0.2, 0.05 * s), Eigen::Vector3d(0.4, -0.2 + 0.1 * s, 0.3));
  }
  const std::vector<double> hold(24, robot.initial_rest_length_m);
  const double e0 = model.kinetic_energy_j() + model.elastic_energy_j();
  ASSERT_GT(model.kinetic_energy_j(), 0.5);
  double worst = 0.0;
  for (int i = 0; i < 10'000; ++i) {
    model.step(hold);
    if (i % 10 == 9) worst = std::max(worst, std::fabs(model.kinetic_energy_j() + model.elastic_energy_j() - e0) / e0);
  }
  // Bullet integrates semi-implicitly in single precision: 2 % over 10 s, as ODE.
  EXPECT_LT(worst, 0.02) << "relative energy error " << worst << " of " << e0 << " J";
}

TEST(BulletEngine, DropsAStrutOntoTheGroundAndHoldsIt) {
  Robot robot = superball(Robot::PhysicsEngine::bullet);
  Model model(robot, robot.time_step_s);
  // Every cable slack: six struts fall freely from the description's pose.
  const std::vector<double> slack(24, robot.motor.max_rest_length_m);
  for (int i = 0; i < 2000; ++i) model.step(slack);
  ASSERT_TRUE(model.state_finite());
  for (int node = 0; node < robot.node_count(); ++node) {
    EXPECT_GT(model.node_position(node).z(), robot.strut_radius_m - 0.005) << "end cap " << node << " sank";
  }
  EXPECT_GT(model.contact_count(), 0);
}

// The crossing struts of model_test.cpp, in Bullet.
double thrown_strut_gap(bool rod_contact) {
  Robot robot = crossing_struts(rod_contact);
  robot.engine = Robot::PhysicsEngine::bullet;
  Model model(robot, 0.001);
  return throw_strut(model);
}

TEST(BulletEngine, StrutsCollideOnlyWithRodContact) {
  EXPECT_LT(thrown_strut_gap(false), -0.03) << "without rod contact the struts pass through";
  const double gap = thrown_strut_gap(true);
  EXPECT_GT(gap, -0.006) << "Bullet let the thrown strut through";
}

TEST(ZeroedAxialSpin, LeavesNoSpinAboutAnyStrutsAxisInEitherEngine) {
  for (const auto engine : {Robot::PhysicsEngine::ode, Robot::PhysicsEngine::bullet}) {
    Robot robot = superball(engine);
    robot.zero_axial_spin = true;
    robot.axial_damping_n_m_s = 0.0;
    Model model(robot, robot.time_step_s);
    for (int s = 0; s < 6; ++s) {
      const auto& strut = robot.struts[s];
      const Eigen::Vector3d axis = (robot.nodes_m[strut.node_b] - robot.nodes_m[strut.node_a]).normalized();
      model.set_velocity(s, Eigen::Vector3d::Zero(), 30.0 * axis + Eigen::Vector3d(0.0, 0.0, 0.5));
    }
    EXPECT_GT(std::fabs(model.axial_spin_rad_per_s(0)), 20.0);
    const std::vector<double> hold(24, robot.initial_rest_length_m);
    model.step(hold);
    for (int s = 0; s < 6; ++s) {
      EXPECT_NEAR(model.axial_spin_rad_per_s(s), 0.0, 1e-5) << "strut " << s;
    }
  }
}

}  // namespace
}  // namespace tensegrity::sim

namespace tensegrity::sim {
namespace {

// fuzz_robot_file found it: an absurd spin damping made ODE abort inside a step,
// and the aborted world then terminated the process when it was destroyed. The
// parser now refuses the value; the engine must survive such a step regardless.
TEST(OdeEngine, AWorldWhoseStepAbortedIsDestroyedCleanly) {
  std::ifstream in(std::string(TENSEGRITY_SOURCE_DIR) + "/fuzz/regressions/robot_file/axial-damping-1e307.json");
  std::stringstream text;
  text << in.rdbuf();
  std::string json = text.str();
  const std::string absurd = "0.1e308";
  ASSERT_NE(json.find(absurd), std::string::npos);
  json.replace(json.find(absurd), absurd.size(), "0.005");
  Robot robot = parse_robot(json, "crash.json");
  robot.axial_damping_n_m_s = 0.1e308;  // past the parser's bound on purpose
  bool threw = false;
  const std::size_t held_before = ode_steppers_held_after_abort();
  {
    Model model(robot, robot.time_step_s);
    model.place(robot.nodes_m);
    const std::vector<double> hold(static_cast<std::size_t>(robot.cable_count()), robot.initial_rest_length_m);
    try {
      for (int i = 0; i < 20 && !model.diverged(); ++i) model.step(hold);
    } catch (const ModelDiverged&) {
      threw = true;
    }
  }  // destroyed here: this used to terminate the process
  EXPECT_TRUE(threw) << "the input no longer makes ODE abort a step: the test tests nothing";
  // Its stepping object, which ODE cannot free, is held (reachable), not lost.
  EXPECT_EQ(ode_steppers_held_after_abort(), held_before + 1);
}

}  // namespace
}  // namespace tensegrity::sim
