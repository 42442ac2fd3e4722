// SPDX-License-Identifier: Apache-2.0
#include "core/motor_loop.hpp"

#include <gtest/gtest.h>

#include "core/rate_limit.hpp"

namespace tensegrity::core {
namespace {

constexpr double kDt = 0.001;

TEST(MoveToward, ReachesTargetExactlyAndNeverOvershoots) {
  EXPECT_DOUBLE_EQ(move_toward(1.0, 0.5, 0.1), 0.9);
  EXPECT_DOUBLE_EQ(move_toward(1.0, 1.5, 0.1), 1.1);
  EXPECT_EQ(move_toward(1.0, 1.05, 0.1), 1.05);
  EXPECT_EQ(move_toward(1.0, 1.0, 0.0), 1.0);
}

TEST(MotorLoop, RateLimitedToMotorSpeed) {
  MotorLimits limits;
  MotorLoop motor;
  motor.reset(0.95);
  double previous = motor.commanded_m();
  int steps = 0;
  while (motor.commanded_m() > 0.75 && steps < 10'000) {
    const auto flags = motor.step(0.75, 50.0, kDt, limits);
    EXPECT_LE(previous - motor.commanded_m(), limits.speed_m_per_s * kDt * (1 + 1e-12));
    if (motor.commanded_m() > 0.75) {
      EXPECT_TRUE(flags & kMotorRateLimited);
    }
    previous = motor.commanded_m();
    ++steps;
  }
  EXPECT_EQ(motor.commanded_m(), 0.75);
  // 0.2 m at 0.2 m/s is one second of 1 ms cycles.
  EXPECT_NEAR(steps, 1000, 1);
}

TEST(MotorLoop, PreferredLengthIsClampedToLimits) {
  MotorLimits limits;
  MotorLoop motor;
  motor.reset(1.09);
  std::uint8_t flags = 0;
  for (int i = 0; i < 200; ++i) flags = motor.step(1.5, 0.0, kDt, limits);
  EXPECT_EQ(motor.commanded_m(), limits.max_rest_length_m);
  EXPECT_TRUE(flags & kMotorClamped);
  motor.reset(0.61);
  for (int i = 0; i < 200; ++i) motor.step(0.1, 0.0, kDt, limits);
  EXPECT_EQ(motor.commanded_m(), limits.min_rest_length_m);
}

TEST(MotorLoop, OutOfRangeStartReturnsAtMotorSpeed) {
  MotorLimits limits;
  MotorLoop motor;
  motor.reset(1.3);  // e.g. a drive that reports a position beyond the limit
  motor.step(1.0, 0.0, kDt, limits);
  EXPECT_DOUBLE_EQ(motor.commanded_m(), 1.3 - limits.speed_m_per_s * kDt);
}

TEST(MotorLoop, CutOffStopsShorteningButAllowsLengthening) {
  MotorLimits limits;
  MotorLoop motor;
  motor.reset(0.9);
  auto flags = motor.step(0.7, limits.cutoff_tension_n + 1.0, kDt, limits);
  EXPECT_EQ(motor.commanded_m(), 0.9);
  EXPECT_TRUE(flags & kMotorCutOff);
  flags = motor.step(1.0, limits.cutoff_tension_n + 1.0, kDt, limits);
  EXPECT_GT(motor.commanded_m(), 0.9);
  EXPECT_FALSE(flags & kMotorCutOff);
  // At the cut-off exactly, shortening is still allowed.
  motor.reset(0.9);
  motor.step(0.7, limits.cutoff_tension_n, kDt, limits);
  EXPECT_LT(motor.commanded_m(), 0.9);
}

TEST(MotorLoop, PayOutGivesCableAtMotorSpeedAboveTheCutOff) {
  MotorLimits limits;
  limits.overload = Overload::pay_out;
  MotorLoop motor;
  motor.reset(0.9);
  const double step_m = limits.speed_m_per_s * kDt;
  // Asked to shorten or to hold, an overloaded motor gives one step of cable.
  auto flags = motor.step(0.7, limits.cutoff_tension_n + 1.0, kDt, limits);
  EXPECT_DOUBLE_EQ(motor.commanded_m(), 0.9 + step_m);
  EXPECT_TRUE(flags & kMotorCutOff);
  flags = motor.step(motor.commanded_m(), limits.cutoff_tension_n + 1.0, kDt, limits);
  EXPECT_DOUBLE_EQ(motor.commanded_m(), 0.9 + 2 * step_m);
  EXPECT_TRUE(flags & kMotorCutOff);
  // Asked to lengthen, it never goes faster than the motor speed.
  const double before = motor.commanded_m();
  flags = motor.step(1.1, limits.cutoff_tension_n + 1.0, kDt, limits);
  EXPECT_DOUBLE_EQ(motor.commanded_m(), before + step_m);
  EXPECT_FALSE(flags & kMotorCutOff);
  // Under the cut-off (or at it) it follows its table again.
  motor.step(0.7, limits.cutoff_tension_n, kDt, limits);
  EXPECT_DOUBLE_EQ(motor.commanded_m(), before);
}

TEST(MotorLoop, PayOutStopsAtTheLongestRestLength) {
  MotorLimits limits;
  limits.overload = Overload::pay_out;
  MotorLoop motor;
  motor.reset(limits.max_rest_length_m - 0.5 * limits.speed_m_per_s * kDt);
  motor.step(0.7, limits.cutoff_tension_n + 1.0, kDt, limits);
  EXPECT_EQ(motor.commanded_m(), limits.max_rest_length_m);
  const auto flags = motor.step(0.7, limits.cutoff_tension_n + 1.0, kDt, limits);
  EXPECT_EQ(motor.commanded_m(), limits.max_rest_length_m);
  EXPECT_TRUE(flags & kMotorCutOff);
}

TEST(MotorLoop, HoldIsTheDefaultOverload) {
  EXPECT_EQ(MotorLimits{}.overload, Overload::hold);
  EXPECT_STREQ(to_string(Overload::hold), "hold");
  EXPECT_STREQ(to_string(Overload::pay_out), "pay_out");
}

TEST(MotorLoop, ZeroOrNegativeDtHolds) {
  MotorLimits limits;
  MotorLoop motor;
  motor.reset(0.9);
  motor.step(0.7, 0.0, 0.0, limits);
  EXPECT_EQ(motor.commanded_m(), 0.9);
  motor.step(0.7, 0.0, -1.0, limits);
  EXPECT_EQ(motor.commanded_m(), 0.9);
}

}  // namespace
}  // namespace tensegrity::core
