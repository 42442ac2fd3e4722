// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/wire/clock_sync.hpp"

#include "firmware/comms/wire/wire_time.hpp"

namespace tensegrity::fw::comms {

bool ClockSyncEstimator::add(std::int64_t t1_ns, std::int64_t t2_ns, std::int64_t t3_ns, std::int64_t t4_ns) {
  // Range first: t2 and t3 come from the wire, and every line below subtracts.
  auto in_range = [](std::int64_t t) { return t >= -kMaxWireTimeNs && t <= kMaxWireTimeNs; };
  if (!in_range(t1_ns) || !in_range(t2_ns) || !in_range(t3_ns) || !in_range(t4_ns)) return false;
  const std::int64_t round_trip = (t4_ns - t1_ns) - (t3_ns - t2_ns);
  if (round_trip < 0 || t4_ns < t1_ns || t3_ns < t2_ns) return false;
  // Halve each difference before adding: clocks far apart must not overflow.
  const std::int64_t offset = (t2_ns - t1_ns) / 2 + (t3_ns - t4_ns) / 2;
  window_[next_] = ClockSample{offset, round_trip, t4_ns};
  next_ = (next_ + 1) % kWindow;
  if (count_ < kWindow) ++count_;
  return true;
}

ClockSample ClockSyncEstimator::best() const {
  if (count_ == 0) return {};
  std::size_t best = 0;
  for (std::size_t i = 1; i < count_; ++i) {
    if (window_[i].round_trip_ns < window_[best].round_trip_ns) best = i;
  }
  return window_[best];
}

}  // namespace tensegrity::fw::comms
