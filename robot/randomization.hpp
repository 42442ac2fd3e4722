// SPDX-License-Identifier: Apache-2.0
#pragma once
// The randomization file (format "tensegrity-randomization/1", docs/reference/files.md):
// the ranges robust learning (`tensegrity evolve --randomize`) draws sampled models
// from. Each range is one field of a perturbation case (robot/perturbation_set.hpp)
// given as [min, max], drawn uniformly; a field not given stays the robot file's.
// Samples are a function of (seed, generation, index) alone: the same on every
// platform, in any thread count, after any resume.
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "robot/perturbation_set.hpp"
#include "robot/robot.hpp"

namespace tensegrity::sim {

class RandomizationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr const char* kRandomizationFormat = "tensegrity-randomization/1";

struct Range {
  double min = 0.0;
  double max = 0.0;
  bool given = false;  // absent from the file: the robot file's value
  std::string why;
};

// The fields in the order they are drawn (the order is part of a sample's identity).
struct Randomization {
  std::string description;
  Range motor_speed_scale;
  Range cable_stiffness_scale;
  Range cable_damping_scale;
  Range strut_mass_scale;
  Range friction_scale;
  Range slope_deg;
  Range slope_azimuth_deg;  // where the ground falls toward, world frame; default [0, 360]
  Range rough_bump_height_m;
  Range rough_bump_spacing_m;
  Range load_cell_noise_n;
  Range load_cell_bias_n;
  Range actuation_delay_s;
  // The file as canonical JSON: the format and the ranges' bounds, without the
  // description and the whys (what a checkpoint records; it parses as a file).
  std::string canonical;
};

// Parses and validates: the format, every range within its field's bounds with
// min <= max. Errors name the source and the field ("r.json: ranges.slope_deg.max: ...").
Randomization parse_randomization(const std::string& json_text, const std::string& source = "randomization");
Randomization load_randomization(const std::filesystem::path& path);

// One sampled model: a perturbation case whose slope (when drawn) falls toward
// slope_azimuth_deg. Its canonical text holds only what changes the model, so that a
// sample equal to another names the same model (and shares its settled start).
struct Sample {
  PerturbationCase change;
  double slope_azimuth_deg = 0.0;
};

// Sample `index` of `generation` for a run of `seed`.
Sample draw_sample(const Randomization& r, std::uint64_t seed, std::int64_t generation, int index);

// `robot` as the sample changes it (perturbed(), its hash naming the sampled model).
Robot sampled_robot(const Robot& robot, const Sample& sample);

}  // namespace tensegrity::sim
