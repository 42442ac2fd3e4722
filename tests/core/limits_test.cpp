// SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "core/limits.hpp"

namespace tensegrity::core {
namespace {

TEST(MotorLimits, DefaultsAreValid) { EXPECT_EQ(validate(MotorLimits{}), LimitsError::none); }

TEST(MotorLimits, EveryLimitMustBeFiniteAndPositive) {
  for (double MotorLimits::*field :
       {&MotorLimits::min_rest_length_m, &MotorLimits::max_rest_length_m, &MotorLimits::speed_m_per_s,
        &MotorLimits::cutoff_tension_n, &MotorLimits::hard_limit_tension_n}) {
    for (const double bad :
         {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
      MotorLimits l;
      l.*field = bad;
      EXPECT_EQ(validate(l), LimitsError::not_positive) << bad;
    }
  }
}

TEST(MotorLimits, RangeMustNotBeEmptyAndTheHardLimitNotBelowTheCutoff) {
  MotorLimits l;
  l.max_rest_length_m = l.min_rest_length_m;
  EXPECT_EQ(validate(l), LimitsError::empty_rest_length_range);
  EXPECT_STREQ(field_of(validate(l)), "max_rest_length_m");
  l = MotorLimits{};
  l.hard_limit_tension_n = l.cutoff_tension_n - 1.0;
  EXPECT_EQ(validate(l), LimitsError::hard_limit_below_cutoff);
  EXPECT_STREQ(field_of(validate(l)), "hard_limit_tension_n");
  EXPECT_EQ(std::string(describe(validate(l))), "must be at least cutoff_tension_n");
  l.hard_limit_tension_n = l.cutoff_tension_n;  // equal: the end cap stops pulling and faults together
  EXPECT_EQ(validate(l), LimitsError::none);
}

}  // namespace
}  // namespace tensegrity::core
