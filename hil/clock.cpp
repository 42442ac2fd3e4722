// SPDX-License-Identifier: Apache-2.0
#include "hil/clock.hpp"

#include <ctime>

#include "hil/pacer.hpp"

namespace tensegrity::hil {

std::int64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void MonotonicClock::sleep_until(std::int64_t deadline_ns, std::int64_t spin_ns) { pace_until(deadline_ns, spin_ns); }

}  // namespace tensegrity::hil
