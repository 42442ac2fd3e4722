// SPDX-License-Identifier: Apache-2.0
#include "view/robot_json.hpp"

#include <nlohmann/json.hpp>

namespace tensegrity::view {

std::string robot_json(const sim::Robot& robot) {
  nlohmann::json struts = nlohmann::json::array();
  for (const auto& s : robot.struts) struts.push_back({s.node_a, s.node_b});
  nlohmann::json cables = nlohmann::json::array();
  nlohmann::json owners = nlohmann::json::array();
  for (const auto& c : robot.cables) {
    cables.push_back({c.node_a, c.node_b});
    owners.push_back(c.owner);
  }
  nlohmann::json nodes = nlohmann::json::array();
  for (const auto& p : robot.nodes_m) nodes.push_back({p.x(), p.y(), p.z()});
  return nlohmann::json{{"name", robot.name},
                        {"hash", robot.hash},
                        {"nodes_m", nodes},
                        {"struts", struts},
                        {"cables", cables},
                        {"cable_owner", owners},
                        {"strut_radius_m", robot.strut_radius_m},
                        {"cutoff_tension_n", robot.motor.cutoff_tension_n},
                        {"hard_limit_tension_n", robot.motor.hard_limit_tension_n},
                        {"min_rest_length_m", robot.motor.min_rest_length_m},
                        {"max_rest_length_m", robot.motor.max_rest_length_m}}
      .dump();
}

}  // namespace tensegrity::view
