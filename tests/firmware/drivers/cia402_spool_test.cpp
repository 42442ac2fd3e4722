// SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "firmware/drivers/cia402.hpp"
#include "firmware/drivers/cia402_power.hpp"
#include "firmware/drivers/spool_geometry.hpp"

namespace tensegrity::fw::canopen {
namespace {

TEST(Cia402, StatuswordDecodesEveryState) {
  using S = Cia402State;
  EXPECT_EQ(decode_statusword(0x0000), S::not_ready_to_switch_on);
  EXPECT_EQ(decode_statusword(0x0250), S::switch_on_disabled);  // remote + voltage bits ignored
  EXPECT_EQ(decode_statusword(0x0231), S::ready_to_switch_on);
  EXPECT_EQ(decode_statusword(0x0233), S::switched_on);
  EXPECT_EQ(decode_statusword(0x0637), S::operation_enabled);
  EXPECT_EQ(decode_statusword(0x0217), S::quick_stop_active);
  EXPECT_EQ(decode_statusword(0x021F), S::fault_reaction_active);
  EXPECT_EQ(decode_statusword(0x0218), S::fault);
  EXPECT_EQ(decode_statusword(0x0001), S::invalid);
  for (int s = 0; s <= static_cast<int>(S::fault); ++s) {
    EXPECT_EQ(decode_statusword(statusword_bits(static_cast<S>(s))), static_cast<S>(s));
  }
}

TEST(Cia402, ControlwordsMatchTheProfile) {
  using C = Cia402Command;
  EXPECT_EQ(controlword_bits(C::shutdown), 0x06);
  EXPECT_EQ(controlword_bits(C::switch_on), 0x07);
  EXPECT_EQ(controlword_bits(C::enable_operation), 0x0F);
  EXPECT_EQ(controlword_bits(C::disable_voltage), 0x00);
  EXPECT_EQ(controlword_bits(C::quick_stop), 0x02);
  EXPECT_EQ(controlword_bits(C::fault_reset), 0x80);
  C c{};
  ASSERT_TRUE(decode_controlword(0x0F, c));
  EXPECT_EQ(c, C::enable_operation);
  ASSERT_TRUE(decode_controlword(0x02, c));
  EXPECT_EQ(c, C::quick_stop);
  ASSERT_TRUE(decode_controlword(0x0D, c));
  EXPECT_EQ(c, C::disable_voltage);
}

TEST(Cia402PowerControl, StepsUpOneTransitionPerCycle) {
  using S = Cia402State;
  Cia402PowerControl p;
  EXPECT_EQ(p.next_controlword(S::switch_on_disabled), 0x00) << "disabled until asked";
  p.request(PowerRequest::operation_enabled);
  EXPECT_EQ(p.next_controlword(S::not_ready_to_switch_on), 0x00);
  EXPECT_EQ(p.next_controlword(S::switch_on_disabled), 0x06);
  EXPECT_EQ(p.next_controlword(S::ready_to_switch_on), 0x07);
  EXPECT_EQ(p.next_controlword(S::switched_on), 0x0F);
  EXPECT_EQ(p.next_controlword(S::operation_enabled), 0x0F);
  EXPECT_EQ(p.next_controlword(S::quick_stop_active), 0x00);
  p.request(PowerRequest::quick_stop);
  EXPECT_EQ(p.next_controlword(S::operation_enabled), 0x02);
  p.request(PowerRequest::disabled);
  EXPECT_EQ(p.next_controlword(S::operation_enabled), 0x00);
}

TEST(Cia402PowerControl, FaultResetOnlyWhenAskedAndAsAnEdge) {
  using S = Cia402State;
  Cia402PowerControl p;
  p.request(PowerRequest::operation_enabled);
  EXPECT_EQ(p.next_controlword(S::fault), 0x00);
  EXPECT_EQ(p.next_controlword(S::fault), 0x00) << "never resets a fault on its own";
  p.request_fault_reset();
  EXPECT_EQ(p.next_controlword(S::fault), 0x80);
  EXPECT_EQ(p.next_controlword(S::fault), 0x00) << "bit 7 dropped to make a new edge";
  EXPECT_EQ(p.next_controlword(S::fault), 0x80);
  EXPECT_EQ(p.next_controlword(S::switch_on_disabled), 0x06);
  EXPECT_FALSE(p.fault_reset_pending());
}

}  // namespace
}  // namespace tensegrity::fw::canopen

namespace tensegrity::fw {
namespace {

TEST(SpoolGeometry, RestLengthCountsRoundTrip) {
  const SpoolGeometry g{0.01, 4096.0 * 109.0, 1.2};
  for (const double length_m : {1.2, 1.0, 0.65, 1.5, 0.0}) {
    const std::int32_t counts = g.counts_from_rest_length(length_m);
    EXPECT_NEAR(g.rest_length_from_counts(counts), length_m, 0.5 / g.counts_per_m());
  }
  for (const std::int32_t counts : {0, 1, -1, 7'105'634, -123'456}) {
    EXPECT_EQ(g.counts_from_rest_length(g.rest_length_from_counts(counts)), counts);
  }
}

TEST(SpoolGeometry, WindingShortensTheCable) {
  const SpoolGeometry g{0.01, 1000.0, 1.0};
  EXPECT_EQ(g.counts_from_rest_length(1.0), 0);
  // One spool turn is 2*pi*r of cable.
  EXPECT_EQ(g.counts_from_rest_length(1.0 - 2.0 * std::numbers::pi * 0.01), 1000);
  EXPECT_EQ(g.counts_from_rest_length(1.0 + 2.0 * std::numbers::pi * 0.01), -1000);
  EXPECT_LT(g.rest_length_from_counts(500), 1.0);
}

TEST(SpoolGeometry, VelocityBothWays) {
  const SpoolGeometry g{0.01, 4096.0 * 109.0, 1.0};
  const std::int32_t shortening = g.counts_per_s_from_rate(-0.2);
  EXPECT_GT(shortening, 0);
  EXPECT_NEAR(shortening, 0.2 * g.counts_per_m(), 0.5);
  EXPECT_NEAR(g.rate_from_counts_per_s(shortening), -0.2, 1e-6);
  EXPECT_NEAR(g.rate_from_counts_per_s(g.counts_per_s_from_rate(0.5)), 0.5, 1e-6);
}

TEST(SpoolGeometry, SaturatesInsteadOfOverflowing) {
  const SpoolGeometry g{0.01, 4096.0 * 109.0, 1.0};
  EXPECT_EQ(g.counts_from_rest_length(-1e6), std::numeric_limits<std::int32_t>::max());
  EXPECT_EQ(g.counts_from_rest_length(1e6), std::numeric_limits<std::int32_t>::min());
  EXPECT_EQ(g.counts_from_rest_length(std::nan("")), 0);
  EXPECT_TRUE(g.valid());
  EXPECT_FALSE((SpoolGeometry{0.0, 1.0, 1.0}.valid()));
}

}  // namespace
}  // namespace tensegrity::fw
