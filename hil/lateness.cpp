// SPDX-License-Identifier: Apache-2.0
#include "hil/lateness.hpp"

namespace tensegrity::hil {

bool LatenessStats::add(std::int64_t lateness_ns) noexcept {
  // Early (a deadline already served by the wait) counts as on time.
  const std::int64_t ns = lateness_ns < 0 ? 0 : lateness_ns;
  const std::int64_t b = ns / kBucketNs;
  ++buckets_[b >= static_cast<std::int64_t>(kBuckets) ? kBuckets - 1 : static_cast<std::size_t>(b)];
  ++count_;
  if (ns > max_ns_) max_ns_ = ns;
  if (ns >= period_ns_) ++missed_;
  const bool late = ns > late_after_ns_;
  if (late) {
    ++late_;
    if (!previous_late_) ++episodes_;
  }
  previous_late_ = late;
  return late;
}

// Upper edge of the bucket holding quantile q: an upper bound within 10 us.
std::int64_t LatenessStats::quantile_ns(double q) const noexcept {
  if (count_ == 0) return 0;
  const auto rank = static_cast<std::int64_t>(q * static_cast<double>(count_ - 1)) + 1;
  std::int64_t seen = 0;
  for (std::size_t b = 0; b < kBuckets; ++b) {
    seen += buckets_[b];
    if (seen >= rank) {
      const std::int64_t edge = static_cast<std::int64_t>(b + 1) * kBucketNs;
      return edge < max_ns_ ? edge : max_ns_;
    }
  }
  return max_ns_;
}

LatenessSummary LatenessStats::summary() const noexcept {
  LatenessSummary s;
  s.steps = count_;
  s.late_steps = late_;
  s.late_episodes = episodes_;
  s.missed_steps = missed_;
  s.late_after_ns = late_after_ns_;
  s.p50_ns = quantile_ns(0.50);
  s.p99_ns = quantile_ns(0.99);
  s.p999_ns = quantile_ns(0.999);
  s.max_ns = max_ns_;
  return s;
}

}  // namespace tensegrity::hil
