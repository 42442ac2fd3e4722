// SPDX-License-Identifier: Apache-2.0
#pragma once
// CLOCK_MONOTONIC in nanoseconds: the one reading of time on the end cap and the
// host (SystemClock, the HIL, the ground station and the view all read it here), so
// that the instants they exchange are on one clock.
#include <cstdint>

namespace tensegrity::fw {

std::int64_t monotonic_ns();

}  // namespace tensegrity::fw
