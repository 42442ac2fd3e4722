// SPDX-License-Identifier: Apache-2.0
#include "robot/perturbation_set.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "format/json_reader.hpp"

namespace tensegrity::sim {
namespace {

using nlohmann::json;
using Reader = format::JsonReader<PerturbationSetError>;

// A scale of a physical quantity: a tenth to ten times the robot file's value is far
// beyond any plausible model error and keeps every scaled robot valid.
double scale(const Reader& r, const char* key, double low) {
  const double s = r.number(key, 1.0);
  if (s < low || s > 10.0) {
    r.fail(key, low > 0.0 ? "must be within [0.1, 10]" : "must be within [0, 10]");
  }
  return s;
}

void parse_ground(const Reader& r, PerturbationCase& c) {
  c.slope_deg = r.non_negative("slope_deg", 0.0);
  if (c.slope_deg > 45.0) r.fail("slope_deg", "must be at most 45 degrees");
  c.slope_heading = static_cast<SlopeHeading>(r.choice("slope_heading", {"uphill", "downhill", "across"}, 0));
  if (r.has("slope_heading") && c.slope_deg == 0.0) r.fail("slope_heading", "needs slope_deg above 0");
  if (!r.has("rough")) return;
  const Reader rough = r.object("rough");
  rough.only({"bump_height_m", "bump_spacing_m", "seed"});
  c.rough.bump_spacing_m = rough.positive("bump_spacing_m", 0.0, true);
  if (c.rough.bump_spacing_m < 0.1 || c.rough.bump_spacing_m > 100.0) {
    rough.fail("bump_spacing_m", "must be within [0.1, 100] m");
  }
  c.rough.bump_height_m = rough.positive("bump_height_m", 0.0, true);
  if (c.rough.bump_height_m > 0.5 * c.rough.bump_spacing_m) {
    rough.fail("bump_height_m", "must be at most half of bump_spacing_m");
  }
  c.rough.seed = rough.count("seed");
  if (c.rough.seed >= (std::uint64_t{1} << 53)) rough.fail("seed", "must be below 2^53 (exact in JSON)");
}

void parse_sensing(const Reader& r, PerturbationCase& c) {
  c.load_cell_noise_n = r.non_negative("load_cell_noise_n", 0.0);
  if (c.load_cell_noise_n > 1000.0) r.fail("load_cell_noise_n", "must be at most 1000 N");
  c.load_cell_bias_n = r.number("load_cell_bias_n", 0.0);
  if (std::abs(c.load_cell_bias_n) > 1000.0) r.fail("load_cell_bias_n", "must be within +-1000 N");
  if (r.has("load_cell_seed")) {
    c.load_cell_seed = r.count("load_cell_seed");
    if (c.load_cell_seed >= (std::uint64_t{1} << 53)) r.fail("load_cell_seed", "must be below 2^53 (exact in JSON)");
  }
  c.actuation_delay_s = r.non_negative("actuation_delay_s", 0.0);
  if (c.actuation_delay_s > 1.0) r.fail("actuation_delay_s", "must be at most 1 s");
}

PerturbationCase parse_case(const Reader& r, const json& element) {
  r.only({"name", "why", "motor_speed_scale", "cable_stiffness_scale", "cable_damping_scale", "strut_mass_scale",
          "friction_scale", "engine", "start_pose", "slope_deg", "slope_heading", "rough", "load_cell_noise_n",
          "load_cell_bias_n", "load_cell_seed", "actuation_delay_s"});
  PerturbationCase c;
  c.name = r.string("name");
  if (r.has("why")) c.why = r.string("why", true);
  c.motor_speed_scale = scale(r, "motor_speed_scale", 0.1);
  c.cable_stiffness_scale = scale(r, "cable_stiffness_scale", 0.1);
  c.cable_damping_scale = scale(r, "cable_damping_scale", 0.0);
  c.strut_mass_scale = scale(r, "strut_mass_scale", 0.1);
  c.friction_scale = scale(r, "friction_scale", 0.0);
  if (r.has("engine")) {
    c.engine = r.choice("engine", {"ode", "bullet"}, 0) == 0 ? Robot::PhysicsEngine::ode : Robot::PhysicsEngine::bullet;
  }
  if (r.has("start_pose")) {
    c.start_pose = r.choice("start_pose", {"face_down", "description"}, 0) == 0 ? Robot::StartPose::face_down
                                                                                : Robot::StartPose::description;
  }
  parse_ground(r, c);
  if (c.engine == Robot::PhysicsEngine::bullet && c.rough.bump_height_m > 0.0) {
    r.fail("rough", "the bullet engine has no rough ground (a slope it has)");
  }
  parse_sensing(r, c);
  json model = element;
  model.erase("name");
  model.erase("why");
  c.canonical = model.dump();
  return c;
}

}  // namespace

PerturbationSet parse_perturbation_set(const std::string& json_text, const std::string& source) {
  const json doc = format::parse_json<PerturbationSetError>(json_text, source);
  const Reader r(doc, source, "");
  r.only({"format", "description", "cases"});
  if (const auto format = r.string("format", true); format != kPerturbationSetFormat) {
    r.fail("format", "expected \"" + std::string(kPerturbationSetFormat) + "\", got \"" + format + "\"");
  }
  PerturbationSet set;
  if (r.has("description")) set.description = r.string("description", true);
  const json& cases = r.array("cases");
  if (cases.empty()) r.fail("cases", "needs at least one case");
  std::set<std::string> names;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const Reader c = r.element("cases", i);
    set.cases.push_back(parse_case(c, cases[i]));
    if (!names.insert(set.cases.back().name).second) c.fail("name", "\"" + set.cases.back().name + "\" is used twice");
  }
  return set;
}

PerturbationSet load_perturbation_set(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw PerturbationSetError(path.string() + ": cannot open perturbation set");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parse_perturbation_set(buffer.str(), path.string());
}

Robot perturbed(const Robot& robot, const PerturbationCase& c, double travel_azimuth_deg) {
  Robot r = robot;
  r.motor.speed_m_per_s *= c.motor_speed_scale;
  for (CableSpec& cable : r.cables) {
    cable.stiffness_n_per_m *= c.cable_stiffness_scale;
    cable.damping_n_s_per_m *= c.cable_damping_scale;
  }
  r.strut_mass_kg *= c.strut_mass_scale;
  r.ground_friction *= c.friction_scale;
  if (c.engine) r.engine = *c.engine;
  if (c.start_pose) r.start_pose = *c.start_pose;
  if (c.slope_deg > 0.0) {
    // The ground falls toward its azimuth: against the travel for an uphill case.
    const double turn = c.slope_heading == SlopeHeading::uphill   ? 180.0
                        : c.slope_heading == SlopeHeading::across ? 90.0
                                                                  : 0.0;
    r.ground_slope_deg = c.slope_deg;
    r.ground_slope_azimuth_deg = std::remainder(travel_azimuth_deg + turn, 360.0);
  }
  if (c.rough.bump_height_m > 0.0) r.ground_rough = c.rough;
  if (r.engine == Robot::PhysicsEngine::bullet && r.ground_rough.bump_height_m > 0.0) {
    throw PerturbationSetError(c.name + ": rough: the bullet engine has no rough ground (a slope it has)");
  }
  char azimuth[32];
  std::snprintf(azimuth, sizeof azimuth, "%.17g", r.ground_slope_azimuth_deg);
  r.hash = fnv1a64_hex(robot.hash + c.canonical + azimuth);
  return r;
}

}  // namespace tensegrity::sim
