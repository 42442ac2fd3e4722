// SPDX-License-Identifier: Apache-2.0
// The end caps' loop period in a HIL run is the robot's time step, decided here and
// nowhere else: the stepper steps physics by time_step_s per tick, each end cap
// plays one loop period per tick, and the DDS start is placed in those ticks. A
// step the end cap cannot run at is refused with the field named.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

#include "hil/hil_error.hpp"
#include "robot/robot.hpp"

namespace tensegrity::hil {

inline constexpr double kMaxEndcapLoopRateHz = 10'000.0;  // firmware/app/config.cpp's limit

inline std::int64_t endcap_period_ns(const sim::Robot& robot) {
  const double dt = robot.time_step_s;
  if (!(dt >= 1.0 / kMaxEndcapLoopRateHz)) {
    throw HilError("robot " + robot.name + ": time_step_s " + std::to_string(dt) +
                   " s: the end caps' loop runs at most 10 kHz, so the HIL needs a step of at least 0.0001 s");
  }
  return static_cast<std::int64_t>(std::llround(dt * 1e9));
}

inline double endcap_loop_rate_hz(const sim::Robot& robot) {
  return 1e9 / static_cast<double>(endcap_period_ns(robot));
}

}  // namespace tensegrity::hil
