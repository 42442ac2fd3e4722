// SPDX-License-Identifier: Apache-2.0
#include "core/limits.hpp"

#include <cmath>
#include <initializer_list>

namespace tensegrity::core {

LimitsError validate(const MotorLimits& l) noexcept {
  for (const double v :
       {l.min_rest_length_m, l.max_rest_length_m, l.speed_m_per_s, l.cutoff_tension_n, l.hard_limit_tension_n}) {
    if (!std::isfinite(v) || !(v > 0.0)) return LimitsError::not_positive;
  }
  if (!(l.max_rest_length_m > l.min_rest_length_m)) return LimitsError::empty_rest_length_range;
  if (!(l.hard_limit_tension_n >= l.cutoff_tension_n)) return LimitsError::hard_limit_below_cutoff;
  return LimitsError::none;
}

const char* describe(LimitsError error) noexcept {
  switch (error) {
    case LimitsError::none: return "ok";
    case LimitsError::not_positive: return "every limit must be a finite number above 0";
    case LimitsError::empty_rest_length_range: return "must be above min_rest_length_m";
    case LimitsError::hard_limit_below_cutoff: return "must be at least cutoff_tension_n";
  }
  return "unknown limits error";
}

const char* field_of(LimitsError error) noexcept {
  switch (error) {
    case LimitsError::empty_rest_length_range: return "max_rest_length_m";
    case LimitsError::hard_limit_below_cutoff: return "hard_limit_tension_n";
    default: return "limits";
  }
}

const char* to_string(Overload overload) noexcept { return kOverloadNames[overload == Overload::pay_out ? 1 : 0]; }

}  // namespace tensegrity::core
