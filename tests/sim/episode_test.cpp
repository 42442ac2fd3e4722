// SPDX-License-Identifier: Apache-2.0
// Episodes: limits, infeasibility, determinism, telemetry, and the control core
// driving the model.
#include "sim/model/episode.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "sim/model/benchmark_policy.hpp"
#include "sim/model/core_controller.hpp"
#include "robot/policy.hpp"

namespace tensegrity::sim {
namespace {

Robot superball() { return load_robot(robot_path_named("superball")); }

// Records what the model did, every step.
class Recorder final : public TelemetrySink {
 public:
  void begin(const Model& model) override { last_.assign(model.rest_length_m().begin(), model.rest_length_m().end()); }
  void record(double, const Model& model) override {
    const auto rest = model.rest_length_m();
    for (std::size_t m = 0; m < rest.size(); ++m) {
      max_rate_ = std::max(max_rate_, std::fabs(rest[m] - last_[m]) / model.dt_s());
      min_ = std::min(min_, rest[m]);
      max_ = std::max(max_, rest[m]);
      rose_ = rose_ || rest[m] > last_[m];
      last_[m] = rest[m];
    }
    ++rows_;
  }
  std::vector<double> last_;
  double max_rate_ = 0.0, min_ = 1e9, max_ = -1e9;
  bool rose_ = false;  // some rest length grew
  int rows_ = 0;
};

// Asks for lengths far outside the limits, alternating every 3 s.
class Extremes final : public Controller {
 public:
  void reset(const Robot&) override {}
  void update(const ControlInput& in, std::span<double> preferred) override {
    const bool odd = static_cast<int>(in.time_s / 3.0) % 2 == 1;
    for (std::size_t m = 0; m < preferred.size(); ++m) preferred[m] = ((m % 2 == 0) == odd) ? 0.1 : 2.0;
  }
};

TEST(Episode, RestLengthsClampedAndRateLimited) {
  Robot robot = superball();
  robot.motor.hard_limit_tension_n = 1e5;  // watch the actuators, not feasibility
  robot.motor.cutoff_tension_n = 1e5;
  Extremes controller;
  Recorder recorder;
  EpisodeOptions options;
  options.duration_s = 9.0;
  options.telemetry = &recorder;
  const auto result = run_episode(robot, controller, options);
  EXPECT_EQ(recorder.rows_, 9000);
  EXPECT_EQ(recorder.min_, robot.motor.min_rest_length_m);
  EXPECT_EQ(recorder.max_, robot.motor.max_rest_length_m);
  EXPECT_LE(recorder.max_rate_, robot.motor.speed_m_per_s * (1.0 + 1e-9));
  EXPECT_GT(recorder.max_rate_, robot.motor.speed_m_per_s * 0.999);
  EXPECT_TRUE(result.feasible);
}

TEST(Episode, TensionPastHardLimitIsInfeasibleNotACrash) {
  Robot robot = superball();
  robot.motor.hard_limit_tension_n = 300.0;
  robot.motor.cutoff_tension_n = 250.0;
  ConstantController controller(robot.motor.min_rest_length_m);
  EpisodeOptions options;
  options.duration_s = 10.0;
  const auto result = run_episode(robot, controller, options);
  EXPECT_FALSE(result.feasible);
  EXPECT_NE(result.infeasible_reason.find("above the hard limit 300 N"), std::string::npos) << result.infeasible_reason;
  EXPECT_GT(result.infeasible_time_s, 0.0);
  EXPECT_LT(result.infeasible_time_s, 10.0);
  EXPECT_LT(result.sim_time_s, 10.0);
  // It ends in the step that broke the limit: a team that scores 0 costs no more.
  EXPECT_EQ(result.sim_time_s, result.infeasible_time_s);
  EXPECT_EQ(result.distance_m, 0.0);
}

TEST(Episode, DivergenceIsInfeasibleNotACrash) {
  Robot robot = superball();
  for (auto& c : robot.cables) c.stiffness_n_per_m = 5e7;  // far too stiff for dt
  robot.motor.hard_limit_tension_n = 1e300;
  robot.motor.cutoff_tension_n = 1e300;
  BenchmarkController controller;
  EpisodeOptions options;
  options.duration_s = 5.0;
  options.start = StartKind::drop;
  const auto result = run_episode(robot, controller, options);
  EXPECT_FALSE(result.feasible);
  EXPECT_FALSE(result.infeasible_reason.empty());
}

TEST(Episode, BitIdenticalAcrossRuns) {
  const Robot robot = superball();
  EpisodeOptions options;
  options.duration_s = 10.0;
  options.start = StartKind::drop;
  BenchmarkController a, b;
  const auto ra = run_episode(robot, a, options);
  const auto rb = run_episode(robot, b, options);
  EXPECT_EQ(ra.displacement_m.x(), rb.displacement_m.x());
  EXPECT_EQ(ra.displacement_m.y(), rb.displacement_m.y());
  EXPECT_EQ(ra.max_tension_n, rb.max_tension_n);
  EXPECT_EQ(ra.mean_tension_n, rb.mean_tension_n);
  EXPECT_EQ(ra.motor_energy_j, rb.motor_energy_j);
  EXPECT_GT(ra.distance_m, 0.01);  // it does move
}

// start.pose "description" drops the description's own pose; settled for 0 s it is
// the drop start exactly, and settled for a while it comes to rest from there.
TEST(Episode, DescriptionPoseStartDropsTheDescriptionsPose) {
  Robot robot = superball();
  robot.start_pose = Robot::StartPose::description;
  robot.settle_s = 0.0;
  robot.hash += "-description-0s";  // the settled start is cached by hash
  const ModelState& settled = settled_state(robot, robot.time_step_s);
  const ModelState dropped = drop_state(robot, robot.time_step_s);
  EXPECT_EQ(settled.body, dropped.body);
  robot.settle_s = 2.0;
  robot.hash += "-2s";
  const ModelState& rested = settled_state(robot, robot.time_step_s);
  const ModelState& face_down = settled_state(superball(), robot.time_step_s);
  ASSERT_EQ(rested.body.size(), dropped.body.size());
  double lowest_before = 1e9, lowest_after = 1e9, apart = 0.0;
  for (std::size_t s = 0; s < dropped.body.size(); s += 13) {  // pos(3) quat(4) linvel(3) angvel(3)
    lowest_before = std::min(lowest_before, dropped.body[s + 2]);
    lowest_after = std::min(lowest_after, rested.body[s + 2]);
    apart = std::max(apart, std::fabs(rested.body[s + 2] - face_down.body[s + 2]));
  }
  EXPECT_LT(lowest_after, lowest_before) << "2 s after the drop the struts are lower";
  EXPECT_GT(apart, 1e-3) << "not the face-down start";
}

TEST(Episode, TelemetryCsvHasOneRowPerRecordedStep) {
  const Robot robot = superball();
  const std::string path = ::testing::TempDir() + "telemetry_test.csv";
  {
    CsvTelemetry csv(path);
    BenchmarkController controller;
    EpisodeOptions options;
    options.duration_s = 0.2;
    options.telemetry = &csv;
    options.telemetry_every = 2;
    run_episode(robot, controller, options);
  }
  std::ifstream in(path);
  std::string header, line;
  std::getline(in, header);
  int rows = 0;
  while (std::getline(in, line)) ++rows;
  EXPECT_EQ(rows, 100);
  EXPECT_EQ(std::count(header.begin(), header.end(), ','),
            3 + 12 * 3 + 24 * 4 + 3);  // after time_s: centre, nodes, cables, energies
  EXPECT_NE(header.find("cable13_tension_n"), std::string::npos);
  EXPECT_NE(header.find("cable23_power_w"), std::string::npos);
  std::remove(path.c_str());
}

Policy constant_policy(const Robot& robot, double value, int complexity = 5) {
  Policy policy;
  policy.robot = robot.name;
  policy.period_s = 4.0;
  policy.complexity = complexity;
  for (int m = 0; m < robot.cable_count(); ++m) {
    policy.cables.push_back({m, robot.cables[m].owner, std::vector<double>(complexity, value)});
  }
  return policy;
}

TEST(Episode, CoreDrivenConstantPolicyEqualsConstantController) {
  // The core's motor loop and the model's actuator share one rate limiter: a policy
  // holding 0.8 m through 12 cores moves the model exactly like a plain controller.
  const Robot robot = superball();
  EpisodeOptions options;
  options.duration_s = 5.0;
  CoreController core(robot, constant_policy(robot, 0.8));
  ConstantController plain(0.8);
  const auto a = run_episode(robot, core, options);
  const auto b = run_episode(robot, plain, options);
  EXPECT_EQ(a.displacement_m.x(), b.displacement_m.x());
  EXPECT_EQ(a.max_tension_n, b.max_tension_n);
  EXPECT_EQ(a.mean_tension_n, b.mean_tension_n);
}

// The 1.7 m robot with a low cut-off and hard limit, which shortening every cable
// to its shortest rest length reaches within 5 s.
Robot low_limit_superball() {
  Robot robot = superball();
  robot.motor.cutoff_tension_n = 150.0;
  robot.motor.hard_limit_tension_n = 300.0;
  return robot;
}

TEST(Episode, CoreCutOffLimitsTensionTheModelSees) {
  // Shortening every cable hard: the cores stop shortening above the cut-off, so the
  // robot stays feasible where a plain controller would not.
  const Robot robot = low_limit_superball();
  EpisodeOptions options;
  options.duration_s = 5.0;
  CoreController core(robot, constant_policy(robot, robot.motor.min_rest_length_m));
  ConstantController plain(robot.motor.min_rest_length_m);
  EXPECT_TRUE(run_episode(robot, core, options).feasible);
  EXPECT_FALSE(run_episode(robot, plain, options).feasible);
}

TEST(Episode, PayingOutMotorsGiveCableAndKeepTensionNearTheCutOff) {
  // The same hard shortening with motors that yield: above the cut-off they give cable
  // (the table never asks for it), so the peak tension is no higher than with holding.
  Robot robot = low_limit_superball();
  EpisodeOptions options;
  options.duration_s = 5.0;
  const Policy shortest = constant_policy(robot, robot.motor.min_rest_length_m);
  CoreController holding(robot, shortest);
  Recorder held;
  options.telemetry = &held;
  const auto hold = run_episode(robot, holding, options);
  EXPECT_FALSE(held.rose_);

  robot.motor.overload = core::Overload::pay_out;
  CoreController yielding(robot, shortest);
  Recorder yielded;
  options.telemetry = &yielded;
  const auto pay_out = run_episode(robot, yielding, options);
  ASSERT_TRUE(hold.feasible);
  ASSERT_TRUE(pay_out.feasible);
  EXPECT_TRUE(yielded.rose_);
  EXPECT_LE(yielded.max_rate_, robot.motor.speed_m_per_s * (1 + 1e-9));
  EXPECT_LE(pay_out.max_tension_n, hold.max_tension_n);
  EXPECT_LT(pay_out.mean_tension_n, hold.mean_tension_n);
}

}  // namespace
}  // namespace tensegrity::sim
