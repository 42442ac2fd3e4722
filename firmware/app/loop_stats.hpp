// SPDX-License-Identifier: Apache-2.0
// Timing of the control loop without allocating (percentiles once per log line and
// at exit, never per cycle).
#pragma once

#include <cstdint>

#include "core/histogram.hpp"

namespace tensegrity::fw::app {

struct TimingSummary {
  std::uint64_t count = 0;
  std::int64_t p50_ns = 0;
  std::int64_t p99_ns = 0;
  std::int64_t max_ns = 0;
};

// 1 us buckets up to 10 ms: a 1 kHz loop's interesting range.
class Histogram : public core::FixedHistogram<1'000, 10'000> {
 public:
  TimingSummary summary() const noexcept { return {count(), quantile_ns(0.50), quantile_ns(0.99), max_ns()}; }
};

}  // namespace tensegrity::fw::app
