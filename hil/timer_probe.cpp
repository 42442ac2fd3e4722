// SPDX-License-Identifier: Apache-2.0
#include "hil/timer_probe.hpp"

#include <cmath>

#include "hil/pacer.hpp"
#include "hil/realtime_priority.hpp"
#include "hil/clock.hpp"

namespace tensegrity::hil {

TimerProbeResult probe_timer_latency(double duration_s, std::int64_t period_ns, std::int64_t spin_ns) {
  const ScopedRealtimePriority priority;
  const ScopedTimerSlack slack(1);
  LatenessStats lateness(period_ns, period_ns / 2);
  const auto steps = static_cast<std::int64_t>(std::llround(duration_s * 1e9 / static_cast<double>(period_ns)));
  const std::int64_t t0 = monotonic_ns() + period_ns;
  for (std::int64_t i = 0; i < steps; ++i) {
    const std::int64_t deadline = t0 + i * period_ns;
    pace_until(deadline, spin_ns);
    lateness.add(monotonic_ns() - deadline);
  }
  return TimerProbeResult{lateness.summary(), priority.active()};
}

}  // namespace tensegrity::hil
