// SPDX-License-Identifier: Apache-2.0
#pragma once
// One motor's loop: moves the commanded rest length toward the preferred one at no
// more than the motor speed, within the rest-length limits, and refuses to shorten
// the cable while its tension is above the cut-off (MotorLimits::overload says whether
// it then holds or pays out).
#include <cstdint>

#include "core/limits.hpp"

namespace tensegrity::core {

enum MotorFlag : std::uint8_t {
  kMotorRateLimited = 1U << 0,  // the preferred length was further than one step away
  kMotorCutOff = 1U << 1,       // shortening suppressed by the tension cut-off
  kMotorClamped = 1U << 2,      // the preferred length was outside the limits
};

class MotorLoop {
 public:
  void reset(double rest_length_m) noexcept { commanded_m_ = rest_length_m; }
  double commanded_m() const noexcept { return commanded_m_; }

  // One control cycle of dt_s seconds; returns MotorFlag bits.
  std::uint8_t step(double preferred_m, double tension_n, double dt_s, const MotorLimits& limits) noexcept;

 private:
  double commanded_m_ = 0.0;
};

}  // namespace tensegrity::core
