// SPDX-License-Identifier: Apache-2.0
// The HIL's time. Every deadline is on CLOCK_MONOTONIC, the clock the kernel's
// timers and the end caps' loops use. The stepper and its tick source read and
// sleep through a Clock they are given, so their pacing and timeouts can be
// tested on a fake one without processes or sleeps.
#pragma once

#include <cstdint>

namespace tensegrity::hil {

// CLOCK_MONOTONIC in nanoseconds (the hub's socket deadlines, the handshake).
std::int64_t monotonic_ns();

class Clock {
 public:
  virtual ~Clock() = default;
  virtual std::int64_t now_ns() const = 0;
  // Returns at `deadline_ns` or later (at once if it has passed). A real clock
  // sleeps to `spin_ns` before it and polls from there (pacer.hpp).
  virtual void sleep_until(std::int64_t deadline_ns, std::int64_t spin_ns) = 0;
};

class MonotonicClock final : public Clock {
 public:
  std::int64_t now_ns() const override { return monotonic_ns(); }
  void sleep_until(std::int64_t deadline_ns, std::int64_t spin_ns) override;
};

}  // namespace tensegrity::hil
