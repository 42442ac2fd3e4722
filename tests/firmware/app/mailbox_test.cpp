// SPDX-License-Identifier: Apache-2.0
// The control loop's lock-free hand-overs under real concurrency: run as they are
// they check order and consistency; under the tsan preset ThreadSanitizer checks
// that every access the two threads share is ordered.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <thread>

#include "firmware/app/mailbox.hpp"

namespace tensegrity::fw::app {
namespace {

constexpr std::uint64_t kItems = 200'000;

TEST(SpscRing, EveryItemArrivesOnceAndInOrderAcrossThreads) {
  SpscRing<std::uint64_t, 64> ring;
  std::uint64_t refused = 0;
  std::thread producer([&] {
    for (std::uint64_t i = 1; i <= kItems; ++i) {
      while (!ring.push(i)) {
        ++refused;
        std::this_thread::yield();
      }
    }
  });
  std::uint64_t expected = 1;
  while (expected <= kItems) {
    std::uint64_t item = 0;
    if (ring.pop(item)) {
      ASSERT_EQ(item, expected);
      ++expected;
    } else {
      std::this_thread::yield();
    }
  }
  producer.join();
  std::uint64_t extra = 0;
  EXPECT_FALSE(ring.pop(extra));
  EXPECT_EQ(ring.dropped(), refused) << "every refused push is counted";
}

TEST(SpscRing, AFullRingRefusesAndKeepsTheOldest) {
  SpscRing<int, 4> ring;
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(ring.push(i));
  EXPECT_FALSE(ring.push(99));
  EXPECT_EQ(ring.dropped(), 1u);
  int item = -1;
  ASSERT_TRUE(ring.pop(item));
  EXPECT_EQ(item, 0);
}

struct Sample {
  std::uint64_t a = 0, b = 0, c = 0;  // always a, 2a, 3a: a torn copy breaks it
};

TEST(LatestValue, TheReaderSeesWholeValuesThatNeverGoBackAcrossThreads) {
  LatestValue<Sample> box;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (std::uint64_t i = 1; i <= kItems; ++i) box.write(Sample{i, 2 * i, 3 * i});
    done.store(true);
  });
  std::uint64_t last = 0, reads = 0;
  Sample s;
  for (;;) {
    const bool finished = done.load();  // before the read: a false read after it means all was read
    if (!box.read(s)) {
      if (finished) break;
      continue;
    }
    ASSERT_EQ(s.b, 2 * s.a);
    ASSERT_EQ(s.c, 3 * s.a);
    ASSERT_GT(s.a, last) << "a read returned an older value than the one before";
    last = s.a;
    ++reads;
  }
  writer.join();
  EXPECT_GT(reads, 0u);
  EXPECT_EQ(last, kItems) << "the newest value is the last one read";
}

TEST(LatestValue, NothingNewReadsFalse) {
  LatestValue<Sample> box;
  Sample s;
  EXPECT_FALSE(box.read(s));
  box.write(Sample{1, 2, 3});
  EXPECT_TRUE(box.read(s));
  EXPECT_FALSE(box.read(s));
}

}  // namespace
}  // namespace tensegrity::fw::app
