// SPDX-License-Identifier: Apache-2.0
#include "firmware/hal/clock.hpp"

#include "firmware/hal/monotonic.hpp"

#include <cerrno>
#include <ctime>

namespace tensegrity::fw {
namespace {
constexpr std::int64_t kNsPerS = 1'000'000'000;
}

std::int64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kNsPerS + ts.tv_nsec;
}

std::int64_t SystemClock::now_ns() const { return monotonic_ns(); }

void SystemClock::sleep_until_ns(std::int64_t deadline_ns) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(deadline_ns / kNsPerS);
  ts.tv_nsec = static_cast<long>(deadline_ns % kNsPerS);
  // An absolute deadline does not drift when a signal interrupts the sleep.
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace tensegrity::fw
