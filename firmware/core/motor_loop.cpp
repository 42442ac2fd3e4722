// SPDX-License-Identifier: Apache-2.0
#include "firmware/core/motor_loop.hpp"

#include "firmware/core/rate_limit.hpp"

namespace tensegrity::core {

std::uint8_t MotorLoop::step(double preferred_m, double tension_n, double dt_s, const MotorLimits& limits) noexcept {
  std::uint8_t flags = 0;
  const double target = clamp_to(preferred_m, limits.min_rest_length_m, limits.max_rest_length_m);
  if (target != preferred_m) flags |= kMotorClamped;

  const double max_step = dt_s > 0.0 ? limits.speed_m_per_s * dt_s : 0.0;
  double next = move_toward(commanded_m_, target, max_step);
  if (next != target) flags |= kMotorRateLimited;

  // Shortening raises tension; paying out never does, so only shortening is cut.
  if (next < commanded_m_ && tension_n > limits.cutoff_tension_n) {
    next = commanded_m_;
    flags |= kMotorCutOff;
  }
  commanded_m_ = next;
  return flags;
}

}  // namespace tensegrity::core
