// SPDX-License-Identifier: Apache-2.0
// The one exception the HIL throws: a run that cannot go on (a missing end cap, a
// failed boot, a bad scenario). The message names what failed, so the launcher
// prints it as the reason for its non-zero exit.
#pragma once

#include <cstdint>
#include <stdexcept>

namespace tensegrity::hil {

class HilError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// CLOCK_MONOTONIC in nanoseconds: every HIL deadline is on this clock.
std::int64_t monotonic_ns();

// Set from a signal handler (SIGINT/SIGTERM in the launcher): the stepper ends the
// run with HilError("interrupted") at the next tick, so shutdown stays orderly.
void request_stop();
bool stop_requested();

}  // namespace tensegrity::hil
