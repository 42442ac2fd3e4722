// SPDX-License-Identifier: Apache-2.0
// The platform's share of real-time lateness: a thread that only paces, exactly as
// the real-time stepper does (same priority, timer slack, sleep-then-spin, absolute
// deadlines, same late threshold) and does nothing else. What it measures is what
// the kernel and the hypervisor cost a 1 kHz loop on this machine (cyclictest's
// question); the stepper's late rate minus this is what the HIL itself adds.
#pragma once

#include <cstdint>

#include "hil/lateness.hpp"

namespace tensegrity::hil {

struct TimerProbeResult {
  LatenessSummary lateness;
  bool sched_fifo = false;  // whether it got the stepper's priority
};

TimerProbeResult probe_timer_latency(double duration_s, std::int64_t period_ns = 1'000'000,
                                     std::int64_t spin_ns = 50'000);

}  // namespace tensegrity::hil
