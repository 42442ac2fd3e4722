// SPDX-License-Identifier: Apache-2.0
// Timing of the control loop without allocating: fixed 1 us buckets up to 10 ms
// (a 1 kHz loop's interesting range; anything longer lands in the last bucket and
// in max). Percentiles are read by scanning the buckets, rarely (once per log line
// and at exit), never per cycle.
#pragma once

#include <array>
#include <cstdint>

namespace tensegrity::fw::app {

struct TimingSummary {
  std::uint64_t count = 0;
  std::int64_t p50_ns = 0;
  std::int64_t p99_ns = 0;
  std::int64_t max_ns = 0;
};

class Histogram {
 public:
  static constexpr std::int64_t kBucketNs = 1'000;
  static constexpr std::size_t kBuckets = 10'000;

  void add(std::int64_t ns) noexcept {
    if (ns < 0) ns = 0;
    const std::int64_t b = ns / kBucketNs;
    ++buckets_[b >= static_cast<std::int64_t>(kBuckets) ? kBuckets - 1 : static_cast<std::size_t>(b)];
    ++count_;
    if (ns > max_ns_) max_ns_ = ns;
  }
  void clear() noexcept {
    buckets_.fill(0);
    count_ = 0;
    max_ns_ = 0;
  }
  // Upper edge of the bucket holding quantile q (0..1): an upper bound within 1 us.
  std::int64_t quantile_ns(double q) const noexcept {
    if (count_ == 0) return 0;
    const auto rank = static_cast<std::uint64_t>(q * static_cast<double>(count_ - 1)) + 1;
    std::uint64_t seen = 0;
    for (std::size_t b = 0; b < kBuckets; ++b) {
      seen += buckets_[b];
      if (seen >= rank) {
        const std::int64_t edge = static_cast<std::int64_t>(b + 1) * kBucketNs;
        return edge < max_ns_ ? edge : max_ns_;
      }
    }
    return max_ns_;
  }
  TimingSummary summary() const noexcept { return {count_, quantile_ns(0.50), quantile_ns(0.99), max_ns_}; }
  std::uint64_t count() const noexcept { return count_; }

 private:
  std::array<std::uint32_t, kBuckets> buckets_{};
  std::uint64_t count_ = 0;
  std::int64_t max_ns_ = 0;
};

}  // namespace tensegrity::fw::app
