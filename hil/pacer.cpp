// SPDX-License-Identifier: Apache-2.0
#include "hil/pacer.hpp"

#include <sys/prctl.h>

#include <cerrno>
#include <ctime>

#include "hil/clock.hpp"

namespace tensegrity::hil {

void pace_until(std::int64_t deadline_ns, std::int64_t spin_ns) {
  const std::int64_t wake_ns = deadline_ns - spin_ns;
  if (monotonic_ns() < wake_ns) {
    const timespec ts{static_cast<time_t>(wake_ns / 1'000'000'000), static_cast<long>(wake_ns % 1'000'000'000)};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    }
  }
  while (monotonic_ns() < deadline_ns) {
  }
}

ScopedTimerSlack::ScopedTimerSlack(unsigned long slack_ns) {
  saved_ = ::prctl(PR_GET_TIMERSLACK, 0, 0, 0, 0);
  if (saved_ >= 0) ::prctl(PR_SET_TIMERSLACK, slack_ns, 0, 0, 0);
}

ScopedTimerSlack::~ScopedTimerSlack() {
  if (saved_ >= 0) ::prctl(PR_SET_TIMERSLACK, static_cast<unsigned long>(saved_), 0, 0, 0);
}

}  // namespace tensegrity::hil
