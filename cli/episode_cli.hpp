// SPDX-License-Identifier: Apache-2.0
#pragma once
// Shared by the subcommands that run episodes: the robot of --robot, the result as
// readable text, and the controller a policy file plays through. The result's JSON
// sits beside its type (sim/model/episode_json.hpp).
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sim/model/controller.hpp"
#include "sim/model/episode.hpp"
#include "sim/model/episode_json.hpp"

namespace tensegrity::cli {

// The robot of a --robot option; the shipped default when empty.
// `path`, else the robot `policy` names (when one is given), else the default robot.
sim::Robot load_robot_arg(const std::string& path, const std::string& policy = "");
using sim::episode_json;
// "heading ... in the start frame (...)": where the robot went, as sim, hil and analyze print it.
void print_heading(const sim::Travel& travel, const std::vector<int>& start_face);
void print_episode_summary(const sim::EpisodeResult& result);
std::unique_ptr<sim::Controller> make_policy_controller(const sim::Robot& robot, const std::string& path);

}  // namespace tensegrity::cli
