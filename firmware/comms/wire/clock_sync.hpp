// SPDX-License-Identifier: Apache-2.0
// NTP-style offset between the host's clock and this end cap's. Each exchange gives
// offset = ((t2-t1)+(t3-t4))/2 and round trip = (t4-t1)-(t3-t2); the true offset
// lies within +- round_trip/2 of the estimate, and the sample with the smallest
// round trip is the one least disturbed by queuing, so that one is kept from a
// sliding window (old samples leave it, so clock drift is followed).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace tensegrity::fw::comms {

struct ClockSample {
  std::int64_t offset_ns = 0;  // host minus local
  std::int64_t round_trip_ns = 0;
  std::int64_t local_time_ns = 0;  // t4
};

class ClockSyncEstimator {
 public:
  static constexpr std::size_t kWindow = 16;

  // Returns false for an impossible sample (negative round trip: a host that
  // answered before it was asked, or clocks read out of order) or a stamp outside
  // +-2^62 ns (wire_time.hpp), checked before any arithmetic.
  bool add(std::int64_t t1_ns, std::int64_t t2_ns, std::int64_t t3_ns, std::int64_t t4_ns);
  bool synced() const { return count_ > 0; }
  // The smallest-round-trip sample of the window; zeros before the first sample.
  ClockSample best() const;
  std::int64_t to_host_ns(std::int64_t local_ns) const { return local_ns + best().offset_ns; }
  std::int64_t to_local_ns(std::int64_t host_ns) const { return host_ns - best().offset_ns; }
  std::size_t samples() const { return count_; }
  void reset() {
    count_ = 0;
    next_ = 0;
  }

 private:
  std::array<ClockSample, kWindow> window_{};
  std::size_t next_ = 0;
  std::size_t count_ = 0;
};

}  // namespace tensegrity::fw::comms
