// SPDX-License-Identifier: Apache-2.0
#pragma once
// The perturbation set file (format "tensegrity-perturbation-set/1",
// docs/reference/files.md): the cases `tensegrity robustness` plays a gait in, each a
// change of the robot (motor speed, cables, masses, ground, engine, start), of its
// sensors (load-cell noise and bias) or of its actuation (a delay). A case changes
// only what it names; every other field is the robot file's.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "robot/robot.hpp"

namespace tensegrity::sim {

class PerturbationSetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr const char* kPerturbationSetFormat = "tensegrity-perturbation-set/1";

// Where a slope case's ground falls, relative to the way the gait rolls on level
// ground: the robot rolls up it, down it, or across it.
enum class SlopeHeading { uphill, downhill, across };

struct PerturbationCase {
  std::string name;  // unique in the set
  std::string why;   // optional: why the range is plausible
  double motor_speed_scale = 1.0;
  double cable_stiffness_scale = 1.0;
  double cable_damping_scale = 1.0;
  double strut_mass_scale = 1.0;
  double friction_scale = 1.0;
  std::optional<Robot::PhysicsEngine> engine;
  std::optional<Robot::StartPose> start_pose;
  double slope_deg = 0.0;
  SlopeHeading slope_heading = SlopeHeading::uphill;
  Robot::RoughGround rough;  // bump_height_m 0: the robot file's ground
  // What the end caps' load cells read: tension + bias + noise, the noise normal
  // with this standard deviation, drawn from load_cell_seed.
  double load_cell_noise_n = 0.0;
  double load_cell_bias_n = 0.0;
  std::uint64_t load_cell_seed = 0;
  // A command reaches the motors this long after the controller gives it.
  double actuation_delay_s = 0.0;
  std::string canonical;  // the case as canonical JSON: names the perturbed model
};

struct PerturbationSet {
  std::string description;
  std::vector<PerturbationCase> cases;
};

// Parses and validates: the format, at least one case, unique names, every field in
// its range. Errors name the source and the field ("set.json: cases[2].slope_deg: ...").
PerturbationSet parse_perturbation_set(const std::string& json_text, const std::string& source = "perturbation set");
PerturbationSet load_perturbation_set(const std::filesystem::path& path);

// `robot` as the case changes it. `travel_azimuth_deg` is the way the gait rolls on
// the robot's own ground (a slope case's heading is relative to it). The result's
// hash names the perturbed model (the nominal hash and the case), so that models
// keyed by it (the settled start) are never mixed up.
Robot perturbed(const Robot& robot, const PerturbationCase& c, double travel_azimuth_deg);

}  // namespace tensegrity::sim
