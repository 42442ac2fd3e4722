// SPDX-License-Identifier: Apache-2.0
#pragma once
// The robot as the page draws it: which end caps each strut and cable joins, who
// owns each cable, the tension cut-off and hard limit that colour the cables, and
// the description's pose (the live view's pose: telemetry carries no positions).
#include <string>

#include "robot/robot.hpp"

namespace tensegrity::view {

std::string robot_json(const sim::Robot& robot);

}  // namespace tensegrity::view
