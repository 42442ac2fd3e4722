// SPDX-License-Identifier: Apache-2.0
#include "view/event_hub.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

namespace tensegrity::view {
namespace {

TEST(EventHub, AReaderGetsEveryEventAfterItJoinedInOrder) {
  EventHub hub;
  hub.publish("old", "{}");
  std::uint64_t cursor = hub.head();
  std::uint64_t skipped = 0;
  hub.publish("a", "{\"n\":1}");
  hub.publish("b", "{\"n\":2}");
  EXPECT_EQ(hub.take(&cursor, 0, &skipped), "event: a\ndata: {\"n\":1}\n\nevent: b\ndata: {\"n\":2}\n\n");
  EXPECT_EQ(hub.take(&cursor, 10, &skipped), "");
  EXPECT_EQ(skipped, 0U);
}

TEST(EventHub, ASlowReaderSkipsAheadAndCountsWhatItLost) {
  EventHub hub(4);
  std::uint64_t cursor = hub.head();
  std::uint64_t skipped = 0;
  for (int i = 0; i < 10; ++i) hub.publish("e", std::to_string(i));
  const std::string got = hub.take(&cursor, 0, &skipped);
  EXPECT_EQ(skipped, 6U);
  EXPECT_EQ(got, "event: e\ndata: 6\n\nevent: e\ndata: 7\n\nevent: e\ndata: 8\n\nevent: e\ndata: 9\n\n");
}

TEST(EventHub, CloseWakesAWaitingReaderAndPublishWakesItAtOnce) {
  EventHub hub;
  std::uint64_t cursor = hub.head();
  std::uint64_t skipped = 0;
  std::thread producer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    hub.publish("x", "1");
  });
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(hub.take(&cursor, 5000, &skipped), "event: x\ndata: 1\n\n");
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(4));
  producer.join();
  std::thread closer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    hub.close();
  });
  EXPECT_EQ(hub.take(&cursor, 5000, &skipped), "");
  EXPECT_TRUE(hub.closed());
  closer.join();
}

TEST(EventHub, CountsReaders) {
  EventHub hub;
  EXPECT_FALSE(hub.wait_for_reader(10));
  hub.reader_joined();
  EXPECT_TRUE(hub.wait_for_reader(10));
  EXPECT_EQ(hub.readers(), 1);
  hub.reader_left();
  EXPECT_EQ(hub.readers(), 0);
}

}  // namespace
}  // namespace tensegrity::view
