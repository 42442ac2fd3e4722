// SPDX-License-Identifier: Apache-2.0
#pragma once
// The gait set file (format "tensegrity-gait-set/1", docs/reference/files.md): the
// gait tables the ground may choose among for one robot, and what each does: the
// face it starts from, the heading it rolls in that face's start frame
// (sim/start_frame.hpp) and its speed. Each gait is a whole policy, played and
// uploaded as any policy file is.
#include <array>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "robot/policy.hpp"
#include "robot/robot.hpp"

namespace tensegrity::sim {

class GaitSetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr const char* kGaitSetFormat = "tensegrity-gait-set/1";

struct Gait {
  std::string name;                // unique in the set
  std::string symmetry;            // the symmetry that made it from the set's source; empty: none
  std::array<int, 3> face{};       // the end caps of the hull face it starts from, increasing
  double heading_deg = 0.0;        // in that face's start frame, (-180, 180]
  double speed_m_per_min = 0.0;    // straight-line distance per minute of rolling
  std::string basis = "symmetry";  // "measured" (this gait was played) or "symmetry" (carried from the source)
  Policy policy;
};

struct GaitSet {
  std::string robot;
  std::string robot_hash;   // of the robot the figures were measured on; empty: not recorded
  std::string source;       // the policy file the set was made from; empty: not recorded
  double duration_s = 0.0;  // the episode length the figures come from
  std::vector<Gait> gaits;
};

// Parses and validates against `robot`: format, robot name, at least one gait, each
// with a unique name, a face of the robot's hull, a heading and a speed in range, a
// basis, and a policy that parse_policy accepts for this robot. Errors name the
// source and the field ("set.json: gaits[2].face: ...").
GaitSet parse_gait_set(const std::string& json_text, const Robot& robot, const std::string& source = "gait set");
GaitSet load_gait_set(const std::filesystem::path& path, const Robot& robot);
std::string gait_set_to_json(const GaitSet& set);
// Atomic, as save_policy.
void save_gait_set(const std::filesystem::path& path, const GaitSet& set);

}  // namespace tensegrity::sim
