// SPDX-License-Identifier: Apache-2.0
// The end caps' loop period in a HIL run is the robot's time step, decided here and
// nowhere else: the stepper steps physics by it per tick, each end cap plays one
// loop period per tick (its config's loop.period_ns, the drives' SYNC and
// interpolation period), and the DDS start is placed in those ticks. The robot
// file's seconds become integer nanoseconds here, once. A step the end cap cannot
// run at is refused with the field named.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

#include "firmware/app/config.hpp"
#include "hil/hil_error.hpp"
#include "robot/robot.hpp"

namespace tensegrity::hil {

inline std::int64_t endcap_period_ns(const sim::Robot& robot) {
  const std::int64_t period_ns = std::llround(robot.time_step_s * 1e9);
  if (const std::string why = fw::app::loop_period_problem(period_ns); !why.empty()) {
    throw HilError("robot " + robot.name + ": time_step_s " + std::to_string(robot.time_step_s) +
                   " s: the end caps' loop period " + why);
  }
  return period_ns;
}

}  // namespace tensegrity::hil
