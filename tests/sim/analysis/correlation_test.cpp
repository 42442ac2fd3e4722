// SPDX-License-Identifier: Apache-2.0
// Pearson's r and the phase-aligned correlation of Figure 12.
#include "sim/analysis/correlation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace tensegrity::sim::analysis {
namespace {

std::vector<double> wave(int n, double phase, double amplitude = 1.0, double offset = 0.0) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(offset + amplitude * std::sin(2.0 * std::numbers::pi * i / n + phase));
  return v;
}

TEST(Correlation, ASignalWithItselfIsOne) {
  const auto a = wave(100, 0.3, 0.2, 0.8);
  EXPECT_NEAR(pearson(a, a), 1.0, 1e-12);
  const auto r = correlation_matrix({a, wave(100, 1.0), wave(100, 2.0)});
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(r[i][i], 1.0, 1e-12);
}

TEST(Correlation, ScaleAndOffsetDoNotMatterSignDoes) {
  const auto a = wave(64, 0.0);
  EXPECT_NEAR(pearson(a, wave(64, 0.0, 0.1, 0.9)), 1.0, 1e-12);
  EXPECT_NEAR(pearson(a, wave(64, std::numbers::pi)), -1.0, 1e-12);
  EXPECT_NEAR(pearson(a, wave(64, std::numbers::pi / 2)), 0.0, 1e-12);  // sine and cosine
}

TEST(Correlation, AConstantSignalMovesWithNothing) {
  const std::vector<double> flat(50, 0.8);
  EXPECT_EQ(pearson(flat, wave(50, 0.0)), 0.0);
  EXPECT_EQ(pearson(flat, flat), 1.0);
}

TEST(Correlation, RejectsSignalsOfDifferentLength) {
  EXPECT_THROW(pearson(wave(10, 0.0), wave(11, 0.0)), std::invalid_argument);
}

TEST(AlignedCorrelation, FindsTheShiftThatLinesUpAShiftedCopy) {
  const int n = 80;
  const auto a = wave(n, 0.0);
  // b is a delayed by 20 samples: b[i] = a[i - 20], so a[i] = b[i + 20].
  const auto b = wave(n, -2.0 * std::numbers::pi * 20 / n);
  EXPECT_LT(pearson(a, b), 0.1);
  const auto best = best_circular_correlation(a, b);
  EXPECT_NEAR(best.r, 1.0, 1e-9);
  EXPECT_EQ(best.lag, 20);
  const auto m = aligned_correlation_matrix({a, b});
  EXPECT_EQ(m.lag[0][1], 20);
  EXPECT_EQ(m.lag[1][0], n - 20);
  EXPECT_NEAR(m.r[1][0], 1.0, 1e-9);
}

}  // namespace
}  // namespace tensegrity::sim::analysis
