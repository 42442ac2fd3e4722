// SPDX-License-Identifier: Apache-2.0
#include "robot/randomization.hpp"

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "format/json_reader.hpp"

namespace tensegrity::sim {
namespace {

using nlohmann::json;
using Reader = format::JsonReader<RandomizationError>;

struct Field {
  const char* key;
  Range Randomization::*range;
  double low;
  double high;
};

// The bounds are the perturbation set's (robot/perturbation_set.cpp): what keeps every
// sampled robot valid. The order is the draw order.
constexpr Field kFields[] = {
    {"motor_speed_scale", &Randomization::motor_speed_scale, 0.1, 10.0},
    {"cable_stiffness_scale", &Randomization::cable_stiffness_scale, 0.1, 10.0},
    {"cable_damping_scale", &Randomization::cable_damping_scale, 0.0, 10.0},
    {"strut_mass_scale", &Randomization::strut_mass_scale, 0.1, 10.0},
    {"friction_scale", &Randomization::friction_scale, 0.0, 10.0},
    {"slope_deg", &Randomization::slope_deg, 0.0, 45.0},
    {"slope_azimuth_deg", &Randomization::slope_azimuth_deg, -360.0, 360.0},
    {"rough_bump_height_m", &Randomization::rough_bump_height_m, 0.0, 50.0},
    {"rough_bump_spacing_m", &Randomization::rough_bump_spacing_m, 0.1, 100.0},
    {"load_cell_noise_n", &Randomization::load_cell_noise_n, 0.0, 1000.0},
    {"load_cell_bias_n", &Randomization::load_cell_bias_n, -1000.0, 1000.0},
    {"actuation_delay_s", &Randomization::actuation_delay_s, 0.0, 1.0},
};

Range parse_range(const Reader& r, double low, double high) {
  r.only({"min", "max", "why"});
  Range range;
  range.given = true;
  range.min = r.number("min");
  range.max = r.number("max");
  const std::string bounds = "must be within [" + json(low).dump() + ", " + json(high).dump() + "]";
  if (range.min < low || range.min > high) r.fail("min", bounds);
  if (range.max < low || range.max > high) r.fail("max", bounds);
  if (range.max < range.min) r.fail("max", "must be at least min");
  if (r.has("why")) range.why = r.string("why", true);
  return range;
}

// What one range needs of another.
void check_together(const Reader& ranges, Randomization& out) {
  if (out.slope_azimuth_deg.given && !out.slope_deg.given) ranges.fail("slope_azimuth_deg", "needs slope_deg");
  if (!out.slope_azimuth_deg.given) out.slope_azimuth_deg = Range{0.0, 360.0, false, {}};
  if (out.rough_bump_spacing_m.given && !out.rough_bump_height_m.given) {
    ranges.fail("rough_bump_spacing_m", "needs rough_bump_height_m");
  }
  if (out.rough_bump_height_m.given && out.rough_bump_height_m.max > 0.0) {
    if (!out.rough_bump_spacing_m.given) ranges.fail("rough_bump_height_m", "needs rough_bump_spacing_m");
    if (out.rough_bump_height_m.max > 0.5 * out.rough_bump_spacing_m.min) {
      ranges.fail("rough_bump_height_m", "max must be at most half of rough_bump_spacing_m.min");
    }
  }
}

// SplitMix64: a small generator specified here bit for bit, so that a sample is the
// same on every platform and standard library.
std::uint64_t mix(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

double draw(std::uint64_t& state, const Range& range) {
  const double u = static_cast<double>(mix(state) >> 11) * 0x1.0p-53;  // in [0, 1)
  return range.min + u * (range.max - range.min);
}

}  // namespace

Randomization parse_randomization(const std::string& json_text, const std::string& source) {
  const json doc = format::parse_json<RandomizationError>(json_text, source);
  const Reader r(doc, source, "");
  r.only({"format", "description", "ranges"});
  if (const auto format = r.string("format", true); format != kRandomizationFormat) {
    r.fail("format", "expected \"" + std::string(kRandomizationFormat) + "\", got \"" + format + "\"");
  }
  Randomization out;
  if (r.has("description")) out.description = r.string("description", true);
  const Reader ranges = r.object("ranges");
  json canonical = json::object();
  for (const auto& [key, value] : r.at("ranges").items()) {
    bool known = false;
    for (const Field& f : kFields) known = known || key == f.key;
    if (!known) ranges.fail(key, "unknown field");
  }
  for (const Field& f : kFields) {
    if (!ranges.has(f.key)) continue;
    out.*f.range = parse_range(ranges.object(f.key), f.low, f.high);
    canonical[f.key] = {{"min", (out.*f.range).min}, {"max", (out.*f.range).max}};
  }
  check_together(ranges, out);
  out.canonical = json{{"format", kRandomizationFormat}, {"ranges", canonical}}.dump();
  return out;
}

Randomization load_randomization(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw RandomizationError(path.string() + ": cannot open randomization file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parse_randomization(buffer.str(), path.string());
}

Sample draw_sample(const Randomization& r, std::uint64_t seed, std::int64_t generation, int index) {
  // One stream per (seed, generation, index): a sample does not depend on how many
  // others are drawn, nor on the coevolution's own engine.
  std::uint64_t state = seed ^ 0x72616e646f6d697aULL;  // "randomiz"
  state = mix(state) + static_cast<std::uint64_t>(generation);
  state = mix(state) + static_cast<std::uint64_t>(index);
  state = mix(state);
  double v[std::size(kFields)];
  // Every field is drawn, given or not, so that adding a range leaves the others' draws.
  for (std::size_t i = 0; i < std::size(kFields); ++i) v[i] = draw(state, r.*kFields[i].range);
  const std::uint64_t rough_seed = mix(state) >> 11;  // below 2^53, exact in JSON
  const std::uint64_t load_cell_seed = mix(state) >> 11;
  Sample s;
  PerturbationCase& c = s.change;
  c.name = "generation " + std::to_string(generation) + " sample " + std::to_string(index);
  json model = json::object();
  const auto take = [&](std::size_t i, double& field) {
    if (!(r.*kFields[i].range).given) return;
    field = v[i];
    model[kFields[i].key] = v[i];
  };
  take(0, c.motor_speed_scale);
  take(1, c.cable_stiffness_scale);
  take(2, c.cable_damping_scale);
  take(3, c.strut_mass_scale);
  take(4, c.friction_scale);
  take(5, c.slope_deg);
  c.slope_heading = SlopeHeading::downhill;           // the ground falls toward slope_azimuth_deg
  if (c.slope_deg > 0.0) s.slope_azimuth_deg = v[6];  // perturbed() hashes the azimuth
  if (r.rough_bump_height_m.given && v[7] > 0.0) {
    c.rough = Robot::RoughGround{v[7], v[8], rough_seed};
    model["rough"] = {{"bump_height_m", v[7]}, {"bump_spacing_m", v[8]}, {"seed", rough_seed}};
  }
  take(9, c.load_cell_noise_n);
  if (c.load_cell_noise_n > 0.0) {
    c.load_cell_seed = load_cell_seed;
    model["load_cell_seed"] = load_cell_seed;
  }
  take(10, c.load_cell_bias_n);
  take(11, c.actuation_delay_s);
  c.canonical = model.dump();
  return s;
}

Robot sampled_robot(const Robot& robot, const Sample& sample) {
  try {
    return perturbed(robot, sample.change, sample.slope_azimuth_deg);
  } catch (const PerturbationSetError& e) {
    throw RandomizationError(e.what());
  }
}

}  // namespace tensegrity::sim
