// SPDX-License-Identifier: Apache-2.0
#include "hil/lateness.hpp"

namespace tensegrity::hil {

bool LatenessStats::add(std::int64_t lateness_ns) noexcept {
  // Early (a deadline already served by the wait) counts as on time.
  const std::int64_t ns = lateness_ns < 0 ? 0 : lateness_ns;
  histogram_.add(ns);
  if (ns >= period_ns_) ++missed_;
  const bool late = ns > late_after_ns_;
  if (late) {
    ++late_;
    if (!previous_late_) {
      ++episodes_;
      stalled_ns_ += ns;  // the first step of an episode is as late as the stall was long
    }
  }
  previous_late_ = late;
  return late;
}

LatenessSummary LatenessStats::summary() const noexcept {
  LatenessSummary s;
  s.steps = static_cast<std::int64_t>(histogram_.count());
  s.late_steps = late_;
  s.late_episodes = episodes_;
  s.missed_steps = missed_;
  s.late_after_ns = late_after_ns_;
  s.p50_ns = histogram_.quantile_ns(0.50);
  s.p99_ns = histogram_.quantile_ns(0.99);
  s.p999_ns = histogram_.quantile_ns(0.999);
  s.max_ns = histogram_.max_ns();
  s.stalled_ns = stalled_ns_;
  return s;
}

}  // namespace tensegrity::hil
