// SPDX-License-Identifier: Apache-2.0
#include "core/histogram.hpp"

#include <gtest/gtest.h>

namespace tensegrity::core {
namespace {

using Us = FixedHistogram<1'000, 100>;  // 1 us buckets to 100 us

TEST(FixedHistogram, EmptyReadsZero) {
  const Us h;
  EXPECT_EQ(h.count(), 0U);
  EXPECT_EQ(h.quantile_ns(0.5), 0);
  EXPECT_EQ(h.max_ns(), 0);
}

TEST(FixedHistogram, QuantileIsTheUpperEdgeOfItsBucketCappedAtMax) {
  Us h;
  for (int i = 1; i <= 100; ++i) h.add(i * 1'000 - 500);  // 0.5, 1.5, ... 99.5 us
  EXPECT_EQ(h.count(), 100U);
  EXPECT_EQ(h.quantile_ns(0.0), 1'000);
  EXPECT_EQ(h.quantile_ns(0.5), 50'000);
  EXPECT_EQ(h.quantile_ns(1.0), 99'500) << "the last bucket's edge is past max";
}

TEST(FixedHistogram, OverflowLandsInTheLastBucketAndMaxKeepsTheTruth) {
  Us h;
  h.add(5'000);
  h.add(7'000'000);
  EXPECT_EQ(h.max_ns(), 7'000'000);
  EXPECT_EQ(h.quantile_ns(1.0), 100'000) << "upper edge of the last bucket";
  EXPECT_EQ(h.quantile_ns(0.0), 6'000);
}

TEST(FixedHistogram, NegativeCountsAsZeroAndClearForgets) {
  Us h;
  h.add(-3'000);
  EXPECT_EQ(h.quantile_ns(0.5), 0) << "capped at max, which is 0";
  h.clear();
  EXPECT_EQ(h.count(), 0U);
  h.add(2'500);
  EXPECT_EQ(h.quantile_ns(0.5), 2'500);
}

}  // namespace
}  // namespace tensegrity::core
