// SPDX-License-Identifier: Apache-2.0
#include "core/motor_loop.hpp"

#include <algorithm>

#include "core/rate_limit.hpp"

namespace tensegrity::core {

std::uint8_t MotorLoop::step(double preferred_m, double tension_n, double dt_s, const MotorLimits& limits) noexcept {
  std::uint8_t flags = 0;
  const double target = clamp_to(preferred_m, limits.min_rest_length_m, limits.max_rest_length_m);
  if (target != preferred_m) flags |= kMotorClamped;

  const double max_step = dt_s > 0.0 ? limits.speed_m_per_s * dt_s : 0.0;
  double next = move_toward(commanded_m_, target, max_step);
  if (next != target) flags |= kMotorRateLimited;

  if (tension_n > limits.cutoff_tension_n) {
    // Shortening raises tension; paying out never does, so only shortening is cut. A
    // yielding motor also gives cable, as far as its speed and the longest rest length allow.
    const double floor_m = limits.overload == Overload::pay_out
                               ? std::min(commanded_m_ + max_step, limits.max_rest_length_m)
                               : commanded_m_;
    if (next < floor_m) {
      next = std::max(floor_m, commanded_m_);
      flags |= kMotorCutOff;
    }
  }
  commanded_m_ = next;
  return flags;
}

}  // namespace tensegrity::core
