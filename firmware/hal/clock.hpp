// SPDX-License-Identifier: Apache-2.0
// Monotonic time for the firmware loops; tests substitute ManualClock so that
// timeouts are exercised without waiting.
#pragma once

#include <cstdint>

namespace tensegrity::fw {

class Clock {
 public:
  virtual ~Clock() = default;
  virtual std::int64_t now_ns() const = 0;
  // Returns at once if `deadline_ns` has passed.
  virtual void sleep_until_ns(std::int64_t deadline_ns) = 0;
};

// CLOCK_MONOTONIC: never jumps with NTP or the user setting the date.
class SystemClock final : public Clock {
 public:
  std::int64_t now_ns() const override;
  void sleep_until_ns(std::int64_t deadline_ns) override;
};

// Time moves only when told; sleeping jumps straight to the deadline.
class ManualClock final : public Clock {
 public:
  explicit ManualClock(std::int64_t start_ns = 0) : now_ns_(start_ns) {}
  std::int64_t now_ns() const override { return now_ns_; }
  void sleep_until_ns(std::int64_t deadline_ns) override {
    if (deadline_ns > now_ns_) now_ns_ = deadline_ns;
  }
  void advance_ns(std::int64_t delta_ns) { now_ns_ += delta_ns; }
  void set_ns(std::int64_t t_ns) { now_ns_ = t_ns; }

 private:
  std::int64_t now_ns_;
};

}  // namespace tensegrity::fw
