// SPDX-License-Identifier: Apache-2.0
#pragma once
// The end cap's control period, one integer in nanoseconds from the robot file (or
// the end cap's config) to the drives: the loop's period, the CANopen SYNC period
// and the drives' interpolation period are the same number.
#include <cstdint>

namespace tensegrity::core {

inline constexpr std::int64_t kDefaultLoopPeriodNs = 1'000'000;  // 1 kHz
inline constexpr std::int64_t kMinLoopPeriodNs = 100'000;        // 10 kHz: the fastest the loop runs
inline constexpr std::int64_t kMaxLoopPeriodNs = 1'000'000'000;  // 1 Hz

}  // namespace tensegrity::core
