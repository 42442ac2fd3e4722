// SPDX-License-Identifier: Apache-2.0
// SCHED_FIFO for the calling thread while in scope, the old policy after. The HIL's
// stepper owns time, so it must not be preempted by the end caps it wakes: their
// loop threads run SCHED_FIFO 80 where allowed (the endcap program asks for it), and
// each datagram of a tick's batch would otherwise switch to the woken end cap before
// the next one is sent (measured: 0.77 ms per tick spent in the send instead of about
// 0.1 ms). One priority above theirs. Refused (not root, no CAP_SYS_NICE): active()
// is false and the thread runs at normal priority.
#pragma once

#include <pthread.h>
#include <sched.h>

namespace tensegrity::hil {

inline constexpr int kStepperPriority = 90;

class ScopedRealtimePriority {
 public:
  explicit ScopedRealtimePriority(int priority = kStepperPriority) {
    saved_ = pthread_getschedparam(pthread_self(), &saved_policy_, &saved_param_) == 0;
    sched_param p{};
    p.sched_priority = priority;
    active_ = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p) == 0;
  }
  ~ScopedRealtimePriority() {
    if (active_ && saved_) pthread_setschedparam(pthread_self(), saved_policy_, &saved_param_);
  }
  ScopedRealtimePriority(const ScopedRealtimePriority&) = delete;
  ScopedRealtimePriority& operator=(const ScopedRealtimePriority&) = delete;
  bool active() const { return active_; }

 private:
  bool saved_ = false;
  int saved_policy_ = SCHED_OTHER;
  sched_param saved_param_{};
  bool active_ = false;
};

}  // namespace tensegrity::hil
