// SPDX-License-Identifier: Apache-2.0
#include "core/table.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace tensegrity::core {
namespace {

EndcapTable make_table(std::uint32_t complexity, double period_s, double phase_s = 0.0) {
  EndcapTable t;
  t.motor_count = 2;
  t.complexity = complexity;
  t.period_s = period_s;
  t.phase_offset_s = phase_s;
  for (std::uint32_t j = 0; j < complexity; ++j) {
    t.rest_length_m[0][j] = 0.7 + 0.05 * j;
    t.rest_length_m[1][j] = 1.0 - 0.02 * j;
  }
  return t;
}

constexpr std::int64_t kMs = 1'000'000;

TEST(TableClock, SubintervalEdgesAreExact) {
  const TableClock clock(make_table(5, 4.0));
  EXPECT_EQ(clock.subinterval(0), 0U);
  EXPECT_EQ(clock.subinterval(800 * kMs - 1), 0U);
  EXPECT_EQ(clock.subinterval(800 * kMs), 1U);
  EXPECT_EQ(clock.subinterval(3200 * kMs - 1), 3U);
  EXPECT_EQ(clock.subinterval(3200 * kMs), 4U);
  EXPECT_EQ(clock.subinterval(4000 * kMs - 1), 4U);
}

TEST(TableClock, PeriodWraps) {
  const TableClock clock(make_table(5, 4.0));
  EXPECT_EQ(clock.subinterval(4000 * kMs), 0U);
  EXPECT_EQ(clock.subinterval(4800 * kMs), 1U);
  EXPECT_EQ(clock.period_index(4000 * kMs - 1), 0);
  EXPECT_EQ(clock.period_index(4000 * kMs), 1);
  EXPECT_EQ(clock.period_index(-1), -1);
  EXPECT_EQ(clock.subinterval(-1), 4U);  // before the start, the previous period plays
  EXPECT_EQ(clock.subinterval(3'600'000 * kMs + 800 * kMs), 1U);
}

TEST(TableClock, PhaseShiftsTheSignal) {
  const TableClock clock(make_table(4, 4.0, 1.0));
  EXPECT_EQ(clock.subinterval(0), 1U);
  EXPECT_EQ(clock.subinterval(2000 * kMs), 3U);
  EXPECT_EQ(clock.subinterval(3000 * kMs), 0U);  // wrapped by the phase
  EXPECT_EQ(clock.period_index(3000 * kMs), 1);
  EXPECT_EQ(clock.period_start_ns(1), 3000 * kMs);
}

TEST(TableClock, NegativePhaseAndPhaseBeyondPeriod) {
  const TableClock a(make_table(4, 4.0, -1.0));
  const TableClock b(make_table(4, 4.0, 3.0));
  for (std::int64_t t = 0; t < 8000 * kMs; t += 250 * kMs) EXPECT_EQ(a.subinterval(t), b.subinterval(t));
  const TableClock c(make_table(4, 4.0, 9.0));  // 9 s == 1 s modulo the period
  const TableClock d(make_table(4, 4.0, 1.0));
  for (std::int64_t t = 0; t < 8000 * kMs; t += 250 * kMs) EXPECT_EQ(c.subinterval(t), d.subinterval(t));
}

TEST(TableClock, ComplexityOneIsConstant) {
  const TableClock clock(make_table(1, 2.5));
  for (std::int64_t t = -5000 * kMs; t < 10000 * kMs; t += 123 * kMs) EXPECT_EQ(clock.subinterval(t), 0U);
}

TEST(TableClock, NonIntegralSubintervalsCoverThePeriod) {
  // 7 subintervals of 4/7 s: every one is hit, in order, once per period.
  const TableClock clock(make_table(7, 4.0));
  std::uint32_t last = 0;
  int changes = 0;
  for (std::int64_t t = 0; t < 4000 * kMs; t += kMs) {
    const auto j = clock.subinterval(t);
    if (j != last) {
      EXPECT_EQ(j, last + 1);
      ++changes;
      last = j;
    }
  }
  EXPECT_EQ(changes, 6);
}

TEST(TableValidate, AcceptsAGoodTable) { EXPECT_EQ(validate(make_table(5, 4.0), 2, MotorLimits{}), TableError::none); }

TEST(TableValidate, RejectsEachBadField) {
  const MotorLimits limits{};
  auto t = make_table(5, 4.0);
  EXPECT_EQ(validate(t, 1, limits), TableError::bad_motor_count);
  t.complexity = 0;
  EXPECT_EQ(validate(t, 2, limits), TableError::bad_complexity);
  t.complexity = kMaxComplexity + 1;
  EXPECT_EQ(validate(t, 2, limits), TableError::bad_complexity);
  t = make_table(5, 0.0);
  EXPECT_EQ(validate(t, 2, limits), TableError::bad_period);
  t = make_table(5, std::numeric_limits<double>::infinity());
  EXPECT_EQ(validate(t, 2, limits), TableError::bad_period);
  t = make_table(5, 4.0, std::nan(""));
  EXPECT_EQ(validate(t, 2, limits), TableError::bad_phase);
  t = make_table(5, 4.0);
  t.rest_length_m[1][3] = std::nan("");
  EXPECT_EQ(validate(t, 2, limits), TableError::non_finite_value);
  t = make_table(5, 4.0);
  t.rest_length_m[0][4] = 1.2;
  EXPECT_EQ(validate(t, 2, limits), TableError::value_out_of_limits);
  t.rest_length_m[0][4] = 0.59;
  EXPECT_EQ(validate(t, 2, limits), TableError::value_out_of_limits);
  EXPECT_STRNE(describe(TableError::value_out_of_limits), "");
}

TEST(TableValidate, IgnoresValuesBeyondComplexity) {
  auto t = make_table(3, 4.0);
  t.rest_length_m[0][5] = std::nan("");  // not part of the table
  EXPECT_EQ(validate(t, 2, MotorLimits{}), TableError::none);
}

}  // namespace
}  // namespace tensegrity::core
