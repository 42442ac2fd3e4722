// SPDX-License-Identifier: Apache-2.0
#include "core/endcap_controller.hpp"

#include <gtest/gtest.h>

#include <array>

#include "tests/support/alloc_counter.hpp"

namespace tensegrity::core {
namespace {

constexpr std::int64_t kMs = 1'000'000;
constexpr double kDt = 0.001;

EndcapTable table_of(double a, double b, std::uint32_t complexity = 2, double period_s = 4.0) {
  EndcapTable t;
  t.motor_count = 2;
  t.complexity = complexity;
  t.period_s = period_s;
  for (std::uint32_t j = 0; j < complexity; ++j) {
    t.rest_length_m[0][j] = (j % 2 == 0) ? a : b;
    t.rest_length_m[1][j] = (j % 2 == 0) ? b : a;
  }
  return t;
}

struct Rig {
  EndcapController controller{EndcapConfig{}};
  std::array<double, 2> tension{50.0, 50.0};
  std::array<double, 2> out{};
  std::int64_t now = 0;
  StepStatus step() {
    const auto s = controller.step(now, kDt, tension, out);
    now += kMs;
    return s;
  }
  void run_ms(int ms) {
    for (int i = 0; i < ms; ++i) step();
  }
};

TEST(EndcapController, IdleHoldsInitialLength) {
  Rig rig;
  rig.run_ms(10);
  EXPECT_EQ(rig.out[0], 0.95);
  EXPECT_EQ(rig.controller.mode(), Mode::idle);
  EXPECT_FALSE(rig.controller.start(0));  // nothing to play
}

TEST(EndcapController, PlaysTheTableThroughTheMotorLoop) {
  Rig rig;
  ASSERT_EQ(rig.controller.load(table_of(0.85, 1.05)), TableError::none);
  ASSERT_TRUE(rig.controller.start(rig.now));
  rig.run_ms(1999);
  // First half: motor 0 toward 0.85 (reached after 0.5 s), motor 1 toward 1.05.
  EXPECT_EQ(rig.out[0], 0.85);
  EXPECT_EQ(rig.out[1], 1.05);
  const auto s = rig.step();  // t = 1.999 s still in subinterval 0
  EXPECT_EQ(s.subinterval, 0U);
  const auto s2 = rig.step();  // t = 2.000 s: subinterval 1
  EXPECT_EQ(s2.subinterval, 1U);
  EXPECT_LT(rig.out[1], 1.05);
}

TEST(EndcapController, HardLimitFaultsAndHoldsUntilCleared) {
  Rig rig;
  ASSERT_EQ(rig.controller.load(table_of(0.7, 1.1)), TableError::none);
  ASSERT_TRUE(rig.controller.start(rig.now));
  rig.run_ms(100);
  const double held = rig.out[0];
  rig.tension[1] = 501.0;
  auto s = rig.step();
  EXPECT_EQ(s.mode, Mode::faulted);
  EXPECT_EQ(s.fault, FaultCause::over_tension);
  EXPECT_EQ(rig.out[0], held);  // the same cycle already holds
  rig.tension[1] = 10.0;
  rig.run_ms(100);
  EXPECT_EQ(rig.out[0], held);  // latched although the tension fell
  EXPECT_FALSE(rig.controller.start(rig.now));
  rig.controller.clear_fault();
  EXPECT_EQ(rig.controller.mode(), Mode::idle);
  EXPECT_TRUE(rig.controller.start(rig.now));
  rig.step();
  EXPECT_NE(rig.out[0], held);
}

TEST(EndcapController, FirstFaultCauseIsKept) {
  Rig rig;
  rig.controller.trip(FaultCause::drive_fault);
  rig.controller.trip(FaultCause::sensor_timeout);
  EXPECT_EQ(rig.controller.fault(), FaultCause::drive_fault);
  EXPECT_STREQ(describe(FaultCause::drive_fault), "motor drive fault");
}

TEST(EndcapController, CutOffReportedPerMotor) {
  Rig rig;
  ASSERT_EQ(rig.controller.load(table_of(0.7, 0.7)), TableError::none);
  ASSERT_TRUE(rig.controller.start(rig.now));
  rig.tension = {450.0, 10.0};
  const auto s = rig.step();
  EXPECT_EQ(s.cutoff_mask, 0b01);
  EXPECT_EQ(rig.out[0], 0.95);
  EXPECT_LT(rig.out[1], 0.95);
}

TEST(EndcapController, RejectedTableLeavesActiveOneRunning) {
  Rig rig;
  ASSERT_EQ(rig.controller.load(table_of(0.8, 1.0)), TableError::none);
  ASSERT_TRUE(rig.controller.start(rig.now));
  auto bad = table_of(0.8, 1.0);
  bad.rest_length_m[1][1] = 2.0;
  EXPECT_EQ(rig.controller.load(bad), TableError::value_out_of_limits);
  EXPECT_FALSE(rig.controller.has_pending_table());
  EXPECT_EQ(rig.controller.active_table().rest_length_m[1][1], 0.8);
  EXPECT_EQ(rig.controller.mode(), Mode::running);
}

TEST(EndcapController, NewTableSwapsInAtPeriodBoundaryOnly) {
  Rig rig;
  ASSERT_EQ(rig.controller.load(table_of(0.8, 1.0, 4, 4.0)), TableError::none);
  ASSERT_TRUE(rig.controller.start(rig.now));
  rig.run_ms(1500);  // mid-period
  ASSERT_EQ(rig.controller.load(table_of(0.7, 0.7, 2, 2.0)), TableError::none);
  EXPECT_TRUE(rig.controller.has_pending_table());
  bool swapped = false;
  std::int64_t swap_time = -1;
  for (int i = 0; i < 5000 && !swapped; ++i) {
    const std::int64_t t = rig.now;
    const auto s = rig.step();
    if (s.table_swapped) {
      swapped = true;
      swap_time = t;
      EXPECT_EQ(s.subinterval, 0U);
    }
  }
  ASSERT_TRUE(swapped);
  EXPECT_EQ(swap_time, 4000 * kMs);  // the old table's period end, not mid-period
  EXPECT_EQ(rig.controller.active_table().period_s, 2.0);
  // The new table's time 0 is the boundary: its own period boundaries follow.
  EXPECT_EQ(rig.controller.table_time_ns(rig.now), 1 * kMs);
}

TEST(EndcapController, LoadWhileIdleIsImmediate) {
  Rig rig;
  ASSERT_EQ(rig.controller.load(table_of(0.8, 1.0)), TableError::none);
  ASSERT_EQ(rig.controller.load(table_of(0.9, 0.9)), TableError::none);
  EXPECT_FALSE(rig.controller.has_pending_table());
  EXPECT_EQ(rig.controller.active_table().rest_length_m[0][0], 0.9);
}

TEST(EndcapController, ShortBuffersTripInsteadOfOverrunning) {
  EndcapController controller{EndcapConfig{}};
  std::array<double, 1> tension{0.0};
  std::array<double, 2> out{};
  const auto s = controller.step(0, kDt, tension, out);
  EXPECT_EQ(s.fault, FaultCause::bad_input);
}

TEST(EndcapController, StepAllocatesNothing) {
  Rig rig;
  ASSERT_EQ(rig.controller.load(table_of(0.8, 1.0, 5)), TableError::none);
  ASSERT_TRUE(rig.controller.start(rig.now));
  ASSERT_EQ(rig.controller.load(table_of(0.7, 1.1, 3)), TableError::none);
  test::AllocationScope scope;
  for (int i = 0; i < 10'000; ++i) {
    rig.tension[0] = (i % 1000 == 0) ? 450.0 : 60.0;
    rig.step();
  }
  rig.controller.trip(FaultCause::emergency_stop);
  rig.step();
  rig.controller.clear_fault();
  EXPECT_EQ(scope.count(), 0U);
}

}  // namespace
}  // namespace tensegrity::core
