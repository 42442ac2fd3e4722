// SPDX-License-Identifier: Apache-2.0
// The end cap's side of the time sync, pure (the node sends and receives). Each
// request carries a fresh random nonce; a reply counts only if it echoes the nonce
// of one of this end cap's outstanding requests, and its t1 is this end cap's own
// record, never the reply's. A reply is held until its request settles (once
// no plausible answer can still come: max_round_trip + max_host_hold after it
// was sent) so that every answer to it is seen:
//
// - implausible: t3 < t2, the host held it longer than max_host_hold, or a round
//   trip < 0 or > max_round_trip: refused;
// - conflicting: two answers to one request whose offsets disagree by more than
//   their round trips allow (a second time source on the domain: a rogue, or a
//   misconfigured host). Neither is believed, and the estimate so far is dropped
//   (it came from one of them): the end cap cannot tell which is the host without
//   authentication (DDS Security), and a wrong offset would place a start in the
//   wrong phase;
// - inconsistent: once synchronized, an offset that disagrees with the current
//   estimate by more than both round trips and drift allow is refused, unless
//   kResyncAfter settled samples in a row agree with each other (the host
//   changed: a restart on another machine), then the estimate starts again.
#pragma once

#include <array>
#include <cstdint>

#include "firmware/comms/wire/clock_sync.hpp"

namespace tensegrity::fw::comms {

struct TimeSyncLimits {
  std::int64_t max_round_trip_ns = 500'000'000;
  std::int64_t max_host_hold_ns = 50'000'000;  // t3 - t2
  std::int64_t tolerance_ns = 1'000'000;       // added to every agreement bound
  // A request settles when no plausible answer can still arrive; later answers
  // are unknown (their nonce is spent). Settling sooner would drop replies the
  // limits allow: on a loaded host (a real-time HIL beside a browser) round trips
  // of 50-300 ms are common, and a 50 ms window left 9 of 12 end caps unsynced.
  std::int64_t settle_after_ns() const { return max_round_trip_ns + max_host_hold_ns; }
};

enum class TimeSyncVerdict : std::uint8_t { held, unknown_nonce, implausible };

struct TimeSyncCounters {
  std::uint64_t accepted = 0;
  std::uint64_t unknown_nonce = 0;
  std::uint64_t implausible = 0;
  std::uint64_t implausible_round_trip = 0;  // of those: the round trip above max_round_trip
  std::uint64_t implausible_hold = 0;        // the host held it above max_host_hold
  std::uint64_t conflicting = 0;
  std::uint64_t inconsistent = 0;
  std::uint64_t resyncs = 0;
};

class TimeSyncClient {
 public:
  static constexpr std::size_t kOutstanding = 8;
  static constexpr int kResyncAfter = 8;

  TimeSyncClient(std::uint64_t nonce_seed, const TimeSyncLimits& limits = {});

  // A new request sent at local time t1; returns its nonce.
  std::uint64_t start_request(std::int64_t t1_ns);
  // One reply, stamped t4 on arrival.
  TimeSyncVerdict on_reply(std::uint64_t nonce, std::int64_t t2_ns, std::int64_t t3_ns, std::int64_t t4_ns);
  // Settles requests sent before now - settle_after (call now and then).
  void settle(std::int64_t now_ns);

  const ClockSyncEstimator& estimator() const { return estimator_; }
  const TimeSyncCounters& counters() const { return counters_; }

 private:
  struct Pending {
    std::uint64_t nonce = 0;
    std::int64_t t1_ns = 0;
    bool used = false;
    int answers = 0;
    bool conflicting = false;
    std::int64_t t2_ns = 0, t3_ns = 0, t4_ns = 0;
  };
  void settle_one(Pending& p);
  std::uint64_t next_nonce();

  TimeSyncLimits limits_;
  std::uint64_t state_;
  std::array<Pending, kOutstanding> pending_{};
  std::size_t next_slot_ = 0;
  ClockSyncEstimator estimator_;
  TimeSyncCounters counters_;
  int disagreeing_in_a_row_ = 0;
  ClockSample disagreeing_{};
};

}  // namespace tensegrity::fw::comms
