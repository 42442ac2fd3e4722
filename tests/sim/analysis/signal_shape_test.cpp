// SPDX-License-Identifier: Apache-2.0
// Peaks per period of a periodic signal.
#include "sim/analysis/signal_shape.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace tensegrity::sim::analysis {
namespace {

std::vector<double> cycle(int harmonics, double amplitude, double phase) {
  std::vector<double> v;
  for (int i = 0; i < 400; ++i) {
    v.push_back(0.85 + amplitude * std::cos(2.0 * std::numbers::pi * harmonics * i / 400.0 + phase));
  }
  return v;
}

TEST(SignalShape, CountsOneOrTwoPeaksWhereverThePeriodStarts) {
  for (const double phase : {0.0, 1.0, 2.5}) {
    EXPECT_EQ(peaks_per_period(cycle(1, 0.1, phase), 0.02), 1);
    EXPECT_EQ(peaks_per_period(cycle(2, 0.1, phase), 0.02), 2);
  }
}

TEST(SignalShape, RipplesBelowTheProminenceAreNotPeaks) {
  auto v = cycle(1, 0.1, 0.0);
  const auto ripple = cycle(7, 0.005, 0.0);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] += ripple[i] - 0.85;
  EXPECT_EQ(peaks_per_period(v, 0.02), 1);
  EXPECT_EQ(peaks_per_period(std::vector<double>(50, 0.8), 0.02), 0);
}

}  // namespace
}  // namespace tensegrity::sim::analysis
