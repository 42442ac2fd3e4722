// SPDX-License-Identifier: Apache-2.0
// The lockstep start grid: both ends of the link rely on it (the end cap rounds a
// start onto it, the HIL places physics step 0 on it), so it lives with the wire
// contract that the ground tools and the HIL link, not in the node's settings.
#pragma once

#include <cstdint>

namespace tensegrity::fw::comms {

// The lockstep start grid in loop periods (start_grid_ns = this x the period):
// 200 ms at 1 kHz. A 50 ms grid failed (tables 1-2 ticks apart) when the 2-core
// host ran other real-time work at load 30 and time-sync errors exceeded 25 ms.
inline constexpr std::int64_t kLockstepStartGridPeriods = 200;

}  // namespace tensegrity::fw::comms
