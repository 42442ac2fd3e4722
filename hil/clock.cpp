// SPDX-License-Identifier: Apache-2.0
#include "hil/clock.hpp"

#include "firmware/hal/monotonic.hpp"
#include "hil/pacer.hpp"

namespace tensegrity::hil {

std::int64_t monotonic_ns() { return fw::monotonic_ns(); }

void MonotonicClock::sleep_until(std::int64_t deadline_ns, std::int64_t spin_ns) { pace_until(deadline_ns, spin_ns); }

}  // namespace tensegrity::hil
