// SPDX-License-Identifier: Apache-2.0
#pragma once
// The one rate limiter of the project: the core's motor loop (the controller) and the
// plants (simulated actuator, emulated drive) all move a rest length with it, so a
// controller and a plant with the same speed agree bit for bit.

namespace tensegrity::core {

// Moves `current` toward `target` by at most `max_step` (>= 0). Returns `target`
// exactly once it is within reach.
constexpr double move_toward(double current, double target, double max_step) noexcept {
  const double delta = target - current;
  if (delta > max_step) return current + max_step;
  if (delta < -max_step) return current - max_step;
  return target;
}

constexpr double clamp_to(double value, double lo, double hi) noexcept {
  return value < lo ? lo : (value > hi ? hi : value);
}

}  // namespace tensegrity::core
