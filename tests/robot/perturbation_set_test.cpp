// SPDX-License-Identifier: Apache-2.0
// The perturbation set file: the shipped default loads, every field is validated
// with its path, and a case changes only what it names.
#include "robot/perturbation_set.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace tensegrity::sim {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

std::string error_of(const json& doc) {
  try {
    parse_perturbation_set(doc.dump(), "set.json");
  } catch (const PerturbationSetError& e) {
    return e.what();
  }
  return "";
}

json one_case(json c) {
  c["name"] = "c";
  return {{"format", kPerturbationSetFormat}, {"cases", json::array({c})}};
}

TEST(PerturbationSet, TheShippedDefaultLoads) {
  const PerturbationSet set =
      load_perturbation_set(std::string(TENSEGRITY_SOURCE_DIR) + "/docs/design/robustness-set.json");
  EXPECT_GE(set.cases.size(), 10U);
  for (const auto& c : set.cases) EXPECT_FALSE(c.why.empty()) << c.name << " says not why it is plausible";
}

TEST(PerturbationSet, EveryFieldIsValidated) {
  EXPECT_THAT(error_of({{"format", "x"}, {"cases", json::array()}}), HasSubstr("set.json: format: expected"));
  EXPECT_THAT(error_of({{"format", kPerturbationSetFormat}, {"cases", json::array()}}),
              HasSubstr("cases: needs at least one case"));
  EXPECT_THAT(error_of({{"format", kPerturbationSetFormat}, {"cases", json::array({json::object()})}}),
              HasSubstr("cases[0].name: missing"));
  const json twice = {{"format", kPerturbationSetFormat}, {"cases", json::array({{{"name", "a"}}, {{"name", "a"}}})}};
  EXPECT_THAT(error_of(twice), HasSubstr("cases[1].name: \"a\" is used twice"));
  EXPECT_THAT(error_of(one_case({{"motor_speed_scale", 0.0}})),
              HasSubstr("cases[0].motor_speed_scale: must be within"));
  EXPECT_THAT(error_of(one_case({{"cable_stiffness_scale", 11}})), HasSubstr("cases[0].cable_stiffness_scale"));
  EXPECT_THAT(error_of(one_case({{"cable_damping_scale", -1}})), HasSubstr("cases[0].cable_damping_scale"));
  EXPECT_THAT(error_of(one_case({{"strut_mass_scale", "x"}})),
              HasSubstr("cases[0].strut_mass_scale: must be a number"));
  EXPECT_THAT(error_of(one_case({{"friction_scale", 20}})), HasSubstr("cases[0].friction_scale"));
  EXPECT_THAT(error_of(one_case({{"engine", "physx"}})), HasSubstr("cases[0].engine: must be \"ode\" or \"bullet\""));
  EXPECT_THAT(error_of(one_case({{"start_pose", "side"}})), HasSubstr("cases[0].start_pose"));
  EXPECT_THAT(error_of(one_case({{"slope_deg", 50}})), HasSubstr("cases[0].slope_deg: must be at most 45"));
  EXPECT_THAT(error_of(one_case({{"slope_heading", "uphill"}})), HasSubstr("cases[0].slope_heading: needs slope_deg"));
  EXPECT_THAT(error_of(one_case({{"slope_deg", 5}, {"slope_heading", "up"}})), HasSubstr("cases[0].slope_heading"));
  EXPECT_THAT(error_of(one_case({{"rough", {{"bump_height_m", 0.05}, {"seed", 1}}}})),
              HasSubstr("cases[0].rough.bump_spacing_m: missing"));
  EXPECT_THAT(error_of(one_case({{"rough", {{"bump_height_m", 0.4}, {"bump_spacing_m", 0.5}, {"seed", 1}}}})),
              HasSubstr("cases[0].rough.bump_height_m: must be at most half"));
  EXPECT_THAT(error_of(one_case(
                  {{"engine", "bullet"}, {"rough", {{"bump_height_m", 0.05}, {"bump_spacing_m", 0.5}, {"seed", 1}}}})),
              HasSubstr("cases[0].rough: the bullet engine has no rough ground"));
  EXPECT_THAT(error_of(one_case({{"load_cell_noise_n", -1}})), HasSubstr("cases[0].load_cell_noise_n: must be >= 0"));
  EXPECT_THAT(error_of(one_case({{"load_cell_bias_n", 2000}})), HasSubstr("cases[0].load_cell_bias_n"));
  EXPECT_THAT(error_of(one_case({{"load_cell_seed", -3}})), HasSubstr("cases[0].load_cell_seed: must be a count"));
  EXPECT_THAT(error_of(one_case({{"actuation_delay_s", 2}})), HasSubstr("cases[0].actuation_delay_s: must be at most"));
  EXPECT_THAT(error_of(one_case({{"motor_speed", 0.8}})), HasSubstr("cases[0].motor_speed: unknown field"));
}

TEST(PerturbationSet, ACaseChangesOnlyWhatItNames) {
  const Robot robot = load_robot(robot_path_named("superball-paper"));
  const PerturbationSet set = parse_perturbation_set(
      one_case({{"motor_speed_scale", 0.8}, {"slope_deg", 5}, {"slope_heading", "uphill"}}).dump());
  const Robot changed = perturbed(robot, set.cases[0], 30.0);
  EXPECT_EQ(changed.motor.speed_m_per_s, robot.motor.speed_m_per_s * 0.8);
  EXPECT_EQ(changed.cables[3].stiffness_n_per_m, robot.cables[3].stiffness_n_per_m);
  EXPECT_EQ(changed.strut_mass_kg, robot.strut_mass_kg);
  EXPECT_EQ(changed.ground_slope_deg, 5.0);
  // Uphill: the ground falls against the way the gait rolls.
  EXPECT_DOUBLE_EQ(changed.ground_slope_azimuth_deg, -150.0);
  EXPECT_NE(changed.hash, robot.hash);
  const Robot again = perturbed(robot, set.cases[0], 30.0);
  EXPECT_EQ(again.hash, changed.hash);
  EXPECT_NE(perturbed(robot, set.cases[0], 31.0).hash, changed.hash) << "another slope, another model";
}

}  // namespace
}  // namespace tensegrity::sim
