// SPDX-License-Identifier: Apache-2.0
#pragma once
// One end cap's share of a policy: a periodic table of preferred rest lengths,
// `complexity` values per motor, each held for period/complexity (the paper's
// "overlapping square waves", section 3).
#include <array>
#include <cstdint>

#include "core/limits.hpp"

namespace tensegrity::core {

// The longest period a table may have: table time is kept in integer nanoseconds.
inline constexpr double kMaxPeriodS = 3600.0;

struct EndcapTable {
  std::uint32_t motor_count = 0;
  std::uint32_t complexity = 0;
  double period_s = 0.0;
  // Shifts the signal: the value played at table time t is the one at t + phase.
  double phase_offset_s = 0.0;
  std::array<std::array<double, kMaxComplexity>, kMaxMotorsPerEndcap> rest_length_m{};
};

enum class TableError : std::uint8_t {
  none = 0,
  bad_motor_count,
  bad_complexity,
  bad_period,
  bad_phase,
  non_finite_value,
  value_out_of_limits,
};

// Static text for logs and acknowledgements; never allocates.
const char* describe(TableError error) noexcept;

// Checks a table against the end cap's motor count and limits. The longest
// accepted period is an hour: table time is kept in integer nanoseconds.
TableError validate(const EndcapTable& table, std::uint32_t expected_motor_count, const MotorLimits& limits) noexcept;

// Time arithmetic of a validated table, in integer nanoseconds so that the firmware,
// the HIL and the simulator pick the same subinterval at the same tick.
class TableClock {
 public:
  TableClock() = default;
  explicit TableClock(const EndcapTable& table) noexcept;

  // Which subinterval (0..complexity-1) plays at table time `time_ns`.
  std::uint32_t subinterval(std::int64_t time_ns) const noexcept;
  // Index of the period containing `time_ns` (floor division; negative before 0).
  std::int64_t period_index(std::int64_t time_ns) const noexcept;
  // Table time at which period `index` begins.
  std::int64_t period_start_ns(std::int64_t index) const noexcept;
  std::int64_t period_ns() const noexcept { return period_ns_; }

 private:
  std::int64_t period_ns_ = 1;
  std::int64_t phase_ns_ = 0;
  std::uint32_t complexity_ = 1;
};

std::int64_t seconds_to_ns(double seconds) noexcept;

}  // namespace tensegrity::core
