// SPDX-License-Identifier: Apache-2.0
// Average linkage against hand-computed trees, and identical signals clustering together.
#include "sim/analysis/clustering.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <numbers>
#include <random>

namespace tensegrity::sim::analysis {
namespace {

TEST(AverageLinkage, MatchesAHandComputedTree) {
  // Points on a line at 0, 1, 5, 6.5: {0,1} at 1, {2,3} at 1.5, then the two pairs at
  // the mean of their four cross distances, (5 + 6.5 + 4 + 5.5) / 4 = 5.25.
  const std::vector<double> x{0.0, 1.0, 5.0, 6.5};
  Matrix d(4, std::vector<double>(4));
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) d[i][j] = std::abs(x[i] - x[j]);
  const Dendrogram t = average_linkage(d);
  ASSERT_EQ(t.merges.size(), 3u);
  EXPECT_EQ(t.merges[0].a, 0);
  EXPECT_EQ(t.merges[0].b, 1);
  EXPECT_DOUBLE_EQ(t.merges[0].height, 1.0);
  EXPECT_EQ(t.merges[1].a, 2);
  EXPECT_EQ(t.merges[1].b, 3);
  EXPECT_DOUBLE_EQ(t.merges[1].height, 1.5);
  EXPECT_EQ(t.merges[2].a, 4);
  EXPECT_EQ(t.merges[2].b, 5);
  EXPECT_DOUBLE_EQ(t.merges[2].height, 5.25);
  EXPECT_EQ(t.merges[2].size, 4);
  EXPECT_EQ(t.leaf_order, (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(cut(t, 2.0), (std::vector<int>{0, 0, 1, 1}));
  EXPECT_EQ(cut(t, 0.5), (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(cut(t, 10.0), (std::vector<int>{0, 0, 0, 0}));
}

TEST(AverageLinkage, UsesTheMeanNotTheClosestPair) {
  // 2 is 2.0 from 0 but 4.0 from 1: average 3.0 > 2.5 to 3, so {0,1} joins 3 first.
  Matrix d{{0, 1, 2, 2.5}, {1, 0, 4, 2.5}, {2, 4, 0, 9}, {2.5, 2.5, 9, 0}};
  const Dendrogram t = average_linkage(d);
  EXPECT_EQ(t.merges[1].a, 3);
  EXPECT_EQ(t.merges[1].b, 4);
  EXPECT_DOUBLE_EQ(t.merges[1].height, 2.5);
  EXPECT_DOUBLE_EQ(t.merges[2].height, (2.0 + 4.0 + 9.0) / 3.0);
}

TEST(AverageLinkage, RejectsAnAsymmetricMatrix) {
  EXPECT_THROW(average_linkage({{0, 1}, {2, 0}}), std::invalid_argument);
}

// Identical signals (shuffled among others) end in the same cluster at height 0,
// whatever the other signals are.
TEST(AverageLinkage, IdenticalSignalsClusterTogether) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  Matrix signals(8, std::vector<double>(120));
  for (auto& s : signals)
    for (auto& v : s) v = noise(rng);
  signals[5] = signals[1];
  signals[7] = signals[1];
  for (auto& v : signals[7]) v = 0.8 + 0.1 * v;  // same shape, other scale
  const Dendrogram t = average_linkage(one_minus(correlation_matrix(signals)));
  const auto labels = cut(t, 1e-9);
  EXPECT_EQ(labels[1], labels[5]);
  EXPECT_EQ(labels[1], labels[7]);
  EXPECT_EQ(std::count(labels.begin(), labels.end(), labels[1]), 3);
  // They are leaves next to each other in the drawing order.
  const auto pos = [&](int leaf) {
    return std::find(t.leaf_order.begin(), t.leaf_order.end(), leaf) - t.leaf_order.begin();
  };
  const auto lo = std::min({pos(1), pos(5), pos(7)});
  const auto hi = std::max({pos(1), pos(5), pos(7)});
  EXPECT_EQ(hi - lo, 2);
  EXPECT_NEAR(t.merges[0].height, 0.0, 1e-12);
  EXPECT_NEAR(t.merges[1].height, 0.0, 1e-12);
}

}  // namespace
}  // namespace tensegrity::sim::analysis
