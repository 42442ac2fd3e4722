// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/logic/time_sync_client.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace tensegrity::fw::comms {
namespace {

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kHour = 3'600'000'000'000;
constexpr std::int64_t kHostAhead = 40'000 * kMs;  // the host's clock vs the end cap's

// An honest host's answer to a request sent at t1: 100 us each way, 20 us inside.
struct Answer {
  std::int64_t t2, t3, t4;
};
Answer honest(std::int64_t t1, std::int64_t offset = kHostAhead) {
  const std::int64_t t2 = t1 + offset + 100'000;
  const std::int64_t t3 = t2 + 20'000;
  return {t2, t3, t3 - offset + 100'000};
}

// Sends a request at `t1`, feeds the answers, settles it.
void exchange(TimeSyncClient& c, std::int64_t t1, std::initializer_list<Answer> answers) {
  const std::uint64_t nonce = c.start_request(t1);
  for (const Answer& a : answers) c.on_reply(nonce, a.t2, a.t3, a.t4);
  c.settle(t1 + 600 * kMs);
}

TEST(TimeSyncClient, AnHonestHostSynchronizesItWithinTheRoundTrip) {
  TimeSyncClient c(42);
  EXPECT_FALSE(c.estimator().synced());
  exchange(c, 1000 * kMs, {honest(1000 * kMs)});
  ASSERT_TRUE(c.estimator().synced());
  EXPECT_LE(std::llabs(c.estimator().best().offset_ns - kHostAhead), c.estimator().best().round_trip_ns / 2);
  EXPECT_EQ(c.counters().accepted, 1U);
}

TEST(TimeSyncClient, ASlowButPlausibleReplyCountsWhenItArrivesAfterOtherRequestsSettled) {
  // A starved host: the reply takes 300 ms. The node settles every cycle; the
  // request must still be open when its answer arrives.
  TimeSyncClient c(42);
  const std::int64_t t1 = 1000 * kMs;
  const std::uint64_t nonce = c.start_request(t1);
  c.settle(t1 + 100 * kMs);
  c.settle(t1 + 250 * kMs);
  const std::int64_t t2 = t1 + kHostAhead + 150 * kMs;
  EXPECT_EQ(c.on_reply(nonce, t2, t2 + 20'000, t1 + 300 * kMs + 20'000), TimeSyncVerdict::held);
  c.settle(t1 + 600 * kMs);
  ASSERT_TRUE(c.estimator().synced());
  EXPECT_EQ(c.counters().accepted, 1U);
  EXPECT_EQ(c.estimator().best().round_trip_ns, 300 * kMs);
}

TEST(TimeSyncClient, RepliesWithoutTheNonceOfAnOutstandingRequestAreRefused) {
  TimeSyncClient c(42);
  const std::uint64_t nonce = c.start_request(1000 * kMs);
  const Answer a = honest(1000 * kMs);
  EXPECT_EQ(c.on_reply(nonce + 1, a.t2, a.t3, a.t4), TimeSyncVerdict::unknown_nonce);
  c.settle(2000 * kMs);
  EXPECT_FALSE(c.estimator().synced());
  // After settling, the nonce is spent: a late (or replayed) answer is unknown too.
  EXPECT_EQ(c.on_reply(nonce, a.t2, a.t3, a.t4), TimeSyncVerdict::unknown_nonce);
  EXPECT_EQ(c.counters().unknown_nonce, 2U);
}

TEST(TimeSyncClient, ImplausibleRepliesAreRefusedWithoutArithmeticOnBadStamps) {
  TimeSyncClient c(42);
  const std::int64_t t1 = 1000 * kMs;
  const Answer a = honest(t1);
  const std::uint64_t n = c.start_request(t1);
  EXPECT_EQ(c.on_reply(n, a.t3, a.t2, a.t4), TimeSyncVerdict::implausible);                        // t3 < t2
  EXPECT_EQ(c.on_reply(n, a.t2, a.t2 + 60 * kMs, a.t4 + 60 * kMs), TimeSyncVerdict::implausible);  // held 60 ms
  EXPECT_EQ(c.on_reply(n, a.t2, a.t3, t1 + 600 * kMs), TimeSyncVerdict::implausible);              // round trip 0.6 s
  EXPECT_EQ(c.on_reply(n, std::numeric_limits<std::int64_t>::min(), a.t3, a.t4), TimeSyncVerdict::implausible);
  EXPECT_EQ(c.on_reply(n, a.t2, std::numeric_limits<std::int64_t>::max(), a.t4), TimeSyncVerdict::implausible);
  c.settle(t1 + 100 * kMs);
  EXPECT_FALSE(c.estimator().synced());
  EXPECT_EQ(c.counters().implausible, 5U);
}

TEST(TimeSyncClient, ARogueAnsweringTheSameRequestsWithAnHourAndZeroRoundTripIsNeverBelieved) {
  TimeSyncClient c(42);
  for (int i = 0; i < 20; ++i) {
    const std::int64_t t1 = (1000 + 25 * i) * kMs;
    const Answer h = honest(t1);
    // The rogue read the request (nonce included): it answers first, an hour off,
    // with t3 - t2 chosen so that the round trip computes to 0.
    const std::int64_t t4 = h.t4;
    const Answer rogue{t1 + kHostAhead + kHour, t1 + kHostAhead + kHour + (t4 - t1), t4};
    exchange(c, t1, {rogue, h});
  }
  EXPECT_FALSE(c.estimator().synced()) << "two disagreeing time sources: neither is believed";
  EXPECT_EQ(c.counters().conflicting, 20U);
}

TEST(TimeSyncClient, ARogueThatSpokeFirstIsDroppedOnceTheHostAnswersToo) {
  TimeSyncClient c(42);
  std::int64_t t1 = 1000 * kMs;
  for (int i = 0; i < 4; ++i, t1 += 25 * kMs) exchange(c, t1, {honest(t1, kHostAhead + kHour)});
  ASSERT_TRUE(c.estimator().synced()) << "alone on the domain, a liar is believed (no authentication)";
  exchange(c, t1, {honest(t1, kHostAhead + kHour), honest(t1)});
  EXPECT_FALSE(c.estimator().synced()) << "two sources disagree: the rogue's estimate is dropped";
}

TEST(TimeSyncClient, OnceSynchronizedALoneDisagreeingSourceIsRefusedUntilItPersists) {
  TimeSyncClient c(42);
  std::int64_t t1 = 1000 * kMs;
  for (int i = 0; i < 4; ++i, t1 += 25 * kMs) exchange(c, t1, {honest(t1)});
  ASSERT_TRUE(c.estimator().synced());
  // The honest host goes quiet; a source an hour off answers alone.
  for (int i = 0; i < TimeSyncClient::kResyncAfter - 1; ++i, t1 += 25 * kMs) {
    exchange(c, t1, {honest(t1, kHostAhead + kHour)});
    EXPECT_LE(std::llabs(c.estimator().best().offset_ns - kHostAhead), kMs) << "sample " << i;
  }
  EXPECT_EQ(c.counters().inconsistent, static_cast<std::uint64_t>(TimeSyncClient::kResyncAfter - 1));
  // A new host that keeps answering consistently is followed in the end.
  exchange(c, t1, {honest(t1, kHostAhead + kHour)});
  EXPECT_EQ(c.counters().resyncs, 1U);
  EXPECT_LE(std::llabs(c.estimator().best().offset_ns - (kHostAhead + kHour)), kMs);
}

}  // namespace
}  // namespace tensegrity::fw::comms
