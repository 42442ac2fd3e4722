// SPDX-License-Identifier: Apache-2.0
#pragma once
// A shipped robot file as JSON to edit, and the error its edited copy gets: the robot
// file's validation tests change one field of a good file and read the message.
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "robot/robot.hpp"

namespace tensegrity::sim::test_files {

inline nlohmann::json shipped_robot_json(const std::string& name) {
  std::ifstream in(robot_path_named(name));
  std::stringstream s;
  s << in.rdbuf();
  return nlohmann::json::parse(s.str());
}

// The RobotError `doc` gets, or "" when it is accepted.
inline std::string robot_error_of(const nlohmann::json& doc) {
  try {
    parse_robot(doc.dump(), "test.json");
  } catch (const RobotError& e) {
    return e.what();
  }
  return "";
}

}  // namespace tensegrity::sim::test_files
