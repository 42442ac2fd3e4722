// SPDX-License-Identifier: Apache-2.0
#include "core/table.hpp"

#include <cmath>

namespace tensegrity::core {
namespace {

std::int64_t floor_div(std::int64_t a, std::int64_t b) noexcept {
  std::int64_t q = a / b;
  if ((a % b != 0) && ((a < 0) != (b < 0))) --q;
  return q;
}
}  // namespace

std::int64_t seconds_to_ns(double seconds) noexcept { return static_cast<std::int64_t>(std::llround(seconds * 1e9)); }

const char* describe(TableError error) noexcept {
  switch (error) {
    case TableError::none: return "ok";
    case TableError::bad_motor_count: return "motor count does not match this end cap";
    case TableError::bad_complexity: return "complexity must be 1..16";
    case TableError::bad_period: return "period must be finite, > 0 and at most 3600 s";
    case TableError::bad_phase: return "phase offset must be finite";
    case TableError::non_finite_value: return "a rest length is not a finite number";
    case TableError::value_out_of_limits: return "a rest length is outside the motor's limits";
  }
  return "unknown table error";
}

TableError validate(const EndcapTable& table, std::uint32_t expected_motor_count, const MotorLimits& limits) noexcept {
  if (table.motor_count != expected_motor_count || table.motor_count == 0 || table.motor_count > kMaxMotorsPerEndcap) {
    return TableError::bad_motor_count;
  }
  if (table.complexity == 0 || table.complexity > kMaxComplexity) return TableError::bad_complexity;
  if (!std::isfinite(table.period_s) || table.period_s <= 0.0 || table.period_s > kMaxPeriodS ||
      seconds_to_ns(table.period_s) < table.complexity) {
    return TableError::bad_period;
  }
  if (!std::isfinite(table.phase_offset_s) || std::fabs(table.phase_offset_s) > kMaxPeriodS) {
    return TableError::bad_phase;
  }
  for (std::uint32_t m = 0; m < table.motor_count; ++m) {
    for (std::uint32_t j = 0; j < table.complexity; ++j) {
      const double v = table.rest_length_m[m][j];
      if (!std::isfinite(v)) return TableError::non_finite_value;
      if (v < limits.min_rest_length_m || v > limits.max_rest_length_m) {
        return TableError::value_out_of_limits;
      }
    }
  }
  return TableError::none;
}

TableClock::TableClock(const EndcapTable& table) noexcept
    : period_ns_(seconds_to_ns(table.period_s)),
      phase_ns_(seconds_to_ns(table.phase_offset_s)),
      complexity_(table.complexity) {
  if (period_ns_ <= 0) period_ns_ = 1;
  if (complexity_ == 0) complexity_ = 1;
  phase_ns_ %= period_ns_;
}

std::int64_t TableClock::period_index(std::int64_t time_ns) const noexcept {
  return floor_div(time_ns + phase_ns_, period_ns_);
}

std::int64_t TableClock::period_start_ns(std::int64_t index) const noexcept { return index * period_ns_ - phase_ns_; }

std::uint32_t TableClock::subinterval(std::int64_t time_ns) const noexcept {
  const std::int64_t within = time_ns + phase_ns_ - period_index(time_ns) * period_ns_;
  // within < period_ns_ <= 3.6e12 and complexity_ <= 16: the product fits in 64 bits.
  const auto j = static_cast<std::uint32_t>(within * complexity_ / period_ns_);
  return j < complexity_ ? j : complexity_ - 1;
}

}  // namespace tensegrity::core
