// SPDX-License-Identifier: Apache-2.0
// The randomization file: the shipped default loads, every field is validated with
// its path, and samples are a function of (seed, generation, index) alone.
#include "robot/randomization.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace tensegrity::sim {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

std::string error_of(const json& doc) {
  try {
    parse_randomization(doc.dump(), "r.json");
  } catch (const RandomizationError& e) {
    return e.what();
  }
  return "";
}

json with(json ranges) { return {{"format", kRandomizationFormat}, {"ranges", std::move(ranges)}}; }
json range(double lo, double hi) { return {{"min", lo}, {"max", hi}}; }

Randomization default_file() {
  return load_randomization(std::string(TENSEGRITY_SOURCE_DIR) + "/docs/design/randomization.json");
}

TEST(Randomization, TheShippedDefaultLoadsAndSaysWhy) {
  const Randomization r = default_file();
  for (const Range* f : {&r.motor_speed_scale, &r.cable_stiffness_scale, &r.cable_damping_scale, &r.strut_mass_scale,
                         &r.friction_scale, &r.slope_deg, &r.rough_bump_height_m, &r.rough_bump_spacing_m,
                         &r.load_cell_noise_n, &r.load_cell_bias_n, &r.actuation_delay_s}) {
    EXPECT_TRUE(f->given);
    EXPECT_FALSE(f->why.empty());
  }
  // The canonical form is itself a file, and the same once read again.
  EXPECT_EQ(parse_randomization(r.canonical).canonical, r.canonical);
}

TEST(Randomization, EveryFieldIsValidated) {
  EXPECT_THAT(error_of({{"format", "x"}, {"ranges", json::object()}}), HasSubstr("r.json: format: expected"));
  EXPECT_THAT(error_of({{"format", kRandomizationFormat}}), HasSubstr("r.json: ranges: missing"));
  EXPECT_THAT(error_of(with({{"speed", range(1, 1)}})), HasSubstr("ranges.speed: unknown field"));
  EXPECT_THAT(error_of(with({{"motor_speed_scale", {{"min", 1}}}})),
              HasSubstr("ranges.motor_speed_scale.max: missing"));
  EXPECT_THAT(error_of(with({{"motor_speed_scale", {{"min", 1}, {"max", 1}, {"mean", 1}}}})),
              HasSubstr("ranges.motor_speed_scale.mean: unknown field"));
  EXPECT_THAT(error_of(with({{"motor_speed_scale", range(1.2, 0.8)}})),
              HasSubstr("ranges.motor_speed_scale.max: must be at least min"));
  EXPECT_THAT(error_of(with({{"motor_speed_scale", {{"min", "a"}, {"max", 1}}}})),
              HasSubstr("ranges.motor_speed_scale.min: must be a number"));
  const std::pair<const char*, json> out_of_bounds[] = {
      {"motor_speed_scale", range(0.05, 1)},   {"cable_stiffness_scale", range(1, 11)},
      {"cable_damping_scale", range(-1, 1)},   {"strut_mass_scale", range(0.0, 1)},
      {"friction_scale", range(1, 20)},        {"slope_deg", range(0, 46)},
      {"rough_bump_height_m", range(-0.1, 0)}, {"load_cell_noise_n", range(-1, 0)},
      {"load_cell_bias_n", range(-2000, 0)},   {"actuation_delay_s", range(0, 2)},
  };
  for (const auto& [key, value] : out_of_bounds) {
    EXPECT_THAT(error_of(with({{key, value}})), HasSubstr(std::string("ranges.") + key + ".")) << key;
    EXPECT_THAT(error_of(with({{key, value}})), HasSubstr("must be within")) << key;
  }
  EXPECT_THAT(error_of(with({{"slope_deg", range(0, 5)}, {"slope_azimuth_deg", range(0, 400)}})),
              HasSubstr("ranges.slope_azimuth_deg.max: must be within"));
  EXPECT_THAT(error_of(with({{"slope_azimuth_deg", range(0, 90)}})),
              HasSubstr("ranges.slope_azimuth_deg: needs slope_deg"));
  EXPECT_THAT(error_of(with({{"rough_bump_height_m", range(0, 0.05)}})),
              HasSubstr("ranges.rough_bump_height_m: needs rough_bump_spacing_m"));
  EXPECT_THAT(error_of(with({{"rough_bump_spacing_m", range(0.5, 1)}})),
              HasSubstr("ranges.rough_bump_spacing_m: needs rough_bump_height_m"));
  EXPECT_THAT(error_of(with({{"rough_bump_height_m", range(0, 0.3)}, {"rough_bump_spacing_m", range(0.5, 1)}})),
              HasSubstr("ranges.rough_bump_height_m: max must be at most half"));
  EXPECT_THAT(error_of(with({{"rough_bump_height_m", range(0, 0.05)}, {"rough_bump_spacing_m", range(0.01, 1)}})),
              HasSubstr("ranges.rough_bump_spacing_m.min: must be within"));
  EXPECT_EQ(error_of(with(json::object())), "");
}

TEST(Randomization, TheSameSeedDrawsTheSameSamplesToTheBit) {
  const Randomization r = default_file();
  const Robot robot = load_robot(robot_path_named("superball-paper"));
  for (int k = 0; k < 4; ++k) {
    const Sample a = draw_sample(r, 7, 3, k);
    const Sample b = draw_sample(r, 7, 3, k);
    EXPECT_EQ(a.change.canonical, b.change.canonical);
    EXPECT_EQ(a.slope_azimuth_deg, b.slope_azimuth_deg);
    EXPECT_EQ(sampled_robot(robot, a).hash, sampled_robot(robot, b).hash);
    // Another index, generation or seed is another model.
    EXPECT_NE(a.change.canonical, draw_sample(r, 7, 3, k + 1).change.canonical);
    EXPECT_NE(a.change.canonical, draw_sample(r, 7, 4, k).change.canonical);
    EXPECT_NE(a.change.canonical, draw_sample(r, 8, 3, k).change.canonical);
    EXPECT_NE(sampled_robot(robot, a).hash, robot.hash);
  }
}

TEST(Randomization, SamplesStayInTheirRanges) {
  const Randomization r = default_file();
  const Robot robot = load_robot(robot_path_named("superball-paper"));
  for (int k = 0; k < 200; ++k) {
    const Sample s = draw_sample(r, 1, k / 8, k % 8);
    const PerturbationCase& c = s.change;
    EXPECT_GE(c.motor_speed_scale, 0.8);
    EXPECT_LT(c.motor_speed_scale, 1.2);
    EXPECT_GE(c.slope_deg, 0.0);
    EXPECT_LT(c.slope_deg, 5.0);
    EXPECT_GE(s.slope_azimuth_deg, 0.0);
    EXPECT_LT(s.slope_azimuth_deg, 360.0);
    EXPECT_LT(c.rough.bump_height_m, 0.05);
    EXPECT_LT(c.actuation_delay_s, 0.05);
    const Robot m = sampled_robot(robot, s);
    EXPECT_EQ(m.motor.speed_m_per_s, robot.motor.speed_m_per_s * c.motor_speed_scale);
    EXPECT_EQ(m.ground_slope_deg, c.slope_deg);
  }
}

TEST(Randomization, ZeroWidthRangesGiveTheSameModelEveryGeneration) {
  const Randomization r =
      parse_randomization(with({{"motor_speed_scale", range(1, 1)}, {"friction_scale", range(0.7, 0.7)}}).dump());
  const Robot robot = load_robot(robot_path_named("superball-paper"));
  const Sample a = draw_sample(r, 1, 1, 0);
  const Sample b = draw_sample(r, 1, 2, 3);
  EXPECT_EQ(a.change.motor_speed_scale, 1.0);
  EXPECT_EQ(a.change.friction_scale, 0.7);
  EXPECT_EQ(a.change.canonical, b.change.canonical);
  EXPECT_EQ(sampled_robot(robot, a).hash, sampled_robot(robot, b).hash);
  EXPECT_EQ(sampled_robot(robot, a).ground_friction, robot.ground_friction * 0.7);
}

}  // namespace
}  // namespace tensegrity::sim
