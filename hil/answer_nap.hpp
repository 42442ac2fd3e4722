// SPDX-License-Identifier: Apache-2.0
// Lockstep: how long the stepper sleeps after sending a tick's SYNCs before it
// starts waiting on the socket for the end caps' answers.
//
// Waiting on the socket wakes the stepper at every answer that finds it asleep:
// about five wake-ups per tick, each a context switch and, in a VM, an
// inter-processor interrupt, paid by the end cap that sends and by the stepper.
// A timer sleep first, for most of the time the answers usually take, leaves
// nobody waiting on the socket while they come in (an answer then costs its
// sender no wake-up) and ends with one timer wake-up that finds most answers
// queued. The latency is measured from the kernel's receive timestamps, so it is
// the end caps' time to answer, not when the stepper happened to look; sleeping
// too long would cost wall time, so the nap is a fraction of the typical latency.
#pragma once

#include <cstdint>

namespace tensegrity::hil {

class AnswerNap {
 public:
  static constexpr double kSmoothing = 0.05;  // weight of a new tick
  static constexpr std::int64_t kMaxNapNs = 1'000'000;

  // `fraction` of the smoothed latency; 0 turns the nap off.
  explicit AnswerNap(double fraction) : fraction_(fraction) {}
  // 0 until a latency has been seen.
  std::int64_t nap_ns() const;
  // The time from the SYNCs' send to the last answer's arrival, one tick.
  void observe(std::int64_t latency_ns);

 private:
  double fraction_;
  double smoothed_ns_ = 0.0;
};

}  // namespace tensegrity::hil
