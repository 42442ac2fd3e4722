// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: a robot description file (robots/*.json). A file the parser
// accepts must build an ODE model that steps without aborting: what the parser
// lets through is what the simulator and the HIL get.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>
#include <vector>

#include "sim/model/model.hpp"
#include "robot/robot.hpp"

namespace sim = tensegrity::sim;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 64 * 1024) return -1;  // robot files are a few kB; bigger inputs only slow the search
  sim::Robot robot;
  try {
    robot = sim::parse_robot(std::string(reinterpret_cast<const char*>(data), size), "fuzz");
  } catch (const sim::RobotError&) {
    return 0;
  }
  try {
    sim::Model model(robot, robot.time_step_s);
    model.place(robot.nodes_m);
    const std::vector<double> preferred(static_cast<std::size_t>(robot.cable_count()), robot.initial_rest_length_m);
    for (int i = 0; i < 20 && !model.diverged(); ++i) model.step(preferred);
  } catch (const sim::ModelDiverged&) {
    // A model that blows up is refused at run time with a clear error: not a crash.
  }
  return 0;
}
