// SPDX-License-Identifier: Apache-2.0
// Pacing the real-time stepper to absolute CLOCK_MONOTONIC deadlines. It sleeps
// with clock_nanosleep(TIMER_ABSTIME) until `spin_ns` before the deadline and
// polls the clock from there: the sleep costs nothing but wakes with the
// scheduler's latency, the spin turns the last stretch into sub-microsecond
// jitter. An absolute deadline does not drift, and a signal does not restart it.
#pragma once

#include <cstdint>

namespace tensegrity::hil {

// Returns at once if the deadline has passed.
void pace_until(std::int64_t deadline_ns, std::int64_t spin_ns);

// A normal (not SCHED_FIFO) thread's timed sleeps end up to its timer slack late
// (50 us by default): 1 ns while pacing, the old value after.
class ScopedTimerSlack {
 public:
  explicit ScopedTimerSlack(unsigned long slack_ns);
  ~ScopedTimerSlack();
  ScopedTimerSlack(const ScopedTimerSlack&) = delete;
  ScopedTimerSlack& operator=(const ScopedTimerSlack&) = delete;

 private:
  int saved_ = -1;
};

}  // namespace tensegrity::hil
