// SPDX-License-Identifier: Apache-2.0
// A fixed-bucket histogram of durations: no allocation, O(1) add, quantiles by a
// scan that callers do rarely (a log line, the end of a run), never per cycle.
// Durations past the last bucket land in it and in max. One template serves the
// firmware's loop timing (1 us buckets) and the HIL's step lateness (10 us).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace tensegrity::core {

template <std::int64_t BucketNs, std::size_t Buckets>
class FixedHistogram {
 public:
  static constexpr std::int64_t kBucketNs = BucketNs;
  static constexpr std::size_t kBuckets = Buckets;

  // Negative durations (early) count as zero.
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
  // Upper edge of the bucket holding quantile q (0..1), capped at max: an upper
  // bound within one bucket.
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
  std::uint64_t count() const noexcept { return count_; }
  std::int64_t max_ns() const noexcept { return max_ns_; }

 private:
  std::array<std::uint32_t, kBuckets> buckets_{};
  std::uint64_t count_ = 0;
  std::int64_t max_ns_ = 0;
};

}  // namespace tensegrity::core
