// SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>

#include <string_view>

#include "firmware/hal/clock.hpp"
#include "firmware/hal/crc32.hpp"

namespace tensegrity::fw {
namespace {

std::span<const std::uint8_t> bytes_of(std::string_view s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

TEST(Crc32, MatchesTheStandardCheckValue) {
  EXPECT_EQ(crc32(bytes_of("123456789")), 0xCBF43926U);
  EXPECT_EQ(crc32(bytes_of("")), 0U);
}

TEST(Crc32, ContinuesAcrossBuffers) {
  const std::uint32_t first = crc32(bytes_of("12345"));
  EXPECT_EQ(crc32(bytes_of("6789"), first), 0xCBF43926U);
}

TEST(ManualClock, MovesOnlyWhenTold) {
  ManualClock clock(100);
  EXPECT_EQ(clock.now_ns(), 100);
  clock.advance_ns(50);
  EXPECT_EQ(clock.now_ns(), 150);
  clock.sleep_until_ns(120);  // in the past: no change
  EXPECT_EQ(clock.now_ns(), 150);
  clock.sleep_until_ns(1'000);
  EXPECT_EQ(clock.now_ns(), 1'000);
}

TEST(SystemClock, IsMonotonicAndSleepsToTheDeadline) {
  SystemClock clock;
  const std::int64_t start_ns = clock.now_ns();
  const std::int64_t deadline_ns = start_ns + 2'000'000;
  clock.sleep_until_ns(deadline_ns);
  EXPECT_GE(clock.now_ns(), deadline_ns);
}

}  // namespace
}  // namespace tensegrity::fw
