// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/rng.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace tensegrity::sim::evolve {
namespace {

TEST(Rng, StateRoundTripsAsText) {
  Rng a(42);
  for (int i = 0; i < 1000; ++i) (void)a.normal();
  Rng b(0);
  b.set_state(a.state());
  for (int i = 0; i < 100; ++i) {
    EXPECT_EQ(a.uniform01(), b.uniform01());
    EXPECT_EQ(a.below(7), b.below(7));
    EXPECT_EQ(a.normal(), b.normal());
  }
}

TEST(Rng, RejectsTextThatIsNotAState) {
  Rng a(1);
  EXPECT_THROW(a.set_state("1 2 3"), std::invalid_argument);
  EXPECT_THROW(a.set_state(a.state() + " junk"), std::invalid_argument);
}

TEST(Rng, FixedSequenceForASeed) {
  // The engine is specified by the standard: its 10000th output for the default
  // seed is fixed ([rand.predef]); our transforms build on it alone.
  std::mt19937_64 reference;
  reference.discard(9999);
  EXPECT_EQ(reference(), 9981545732273789042ULL);
}

TEST(Rng, TransformsHaveTheRightRangeAndMoments) {
  Rng rng(3);
  double sum = 0.0;
  double sum_sq = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double u = rng.uniform(0.6, 1.1);
    ASSERT_GE(u, 0.6);
    ASSERT_LT(u, 1.1);
    ASSERT_LT(rng.below(10), 10u);
    const double z = rng.normal();
    sum += z;
    sum_sq += z * z;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.01);
  EXPECT_NEAR(sum_sq / n, 1.0, 0.02);
}

}  // namespace
}  // namespace tensegrity::sim::evolve
