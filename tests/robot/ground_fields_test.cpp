// SPDX-License-Identifier: Apache-2.0
// The robot file's ground beyond the plane: slope and rough ground are optional,
// leave every existing file's hash alone, and are refused field by field.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "robot/robot.hpp"
#include "tests/robot/robot_json.hpp"

namespace tensegrity::sim {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

json paper_json() { return test_files::shipped_robot_json("superball-paper"); }

std::string error_of(const json& doc) { return test_files::robot_error_of(doc); }

TEST(GroundFields, AbsentMeansTheLevelPlaneAndTheSameHash) {
  const json doc = paper_json();
  const Robot robot = parse_robot(doc.dump(), "test.json");
  EXPECT_EQ(robot.ground_slope_deg, 0.0);
  EXPECT_EQ(robot.ground_rough.bump_height_m, 0.0);
  EXPECT_EQ(robot.hash, load_robot(robot_path_named("superball-paper")).hash);
}

TEST(GroundFields, SlopeAndRoughAreReadAndNameAnotherModel) {
  json doc = paper_json();
  doc["ground"]["slope_deg"] = 10.0;
  doc["ground"]["slope_azimuth_deg"] = -90.0;
  doc["ground"]["rough"] = {{"bump_height_m", 0.05}, {"bump_spacing_m", 0.5}, {"seed", 7}};
  const Robot robot = parse_robot(doc.dump(), "test.json");
  EXPECT_EQ(robot.ground_slope_deg, 10.0);
  EXPECT_EQ(robot.ground_slope_azimuth_deg, -90.0);
  EXPECT_EQ(robot.ground_rough.bump_height_m, 0.05);
  EXPECT_EQ(robot.ground_rough.bump_spacing_m, 0.5);
  EXPECT_EQ(robot.ground_rough.seed, 7U);
  // The ground is part of the model a policy records: a gait played on a slope is
  // played on another robot than the one it was learned on, and says so.
  EXPECT_NE(robot.hash, load_robot(robot_path_named("superball-paper")).hash);
}

TEST(GroundFields, EveryFieldIsValidated) {
  const auto refused = [](const char* key, const json& value) {
    json doc = paper_json();
    doc["ground"][key] = value;
    return error_of(doc);
  };
  EXPECT_THAT(refused("slope_deg", -1.0), HasSubstr("ground.slope_deg: must be >= 0"));
  EXPECT_THAT(refused("slope_deg", 46.0), HasSubstr("ground.slope_deg: must be at most 45 degrees"));
  EXPECT_THAT(refused("slope_deg", "steep"), HasSubstr("ground.slope_deg: must be a number"));
  EXPECT_THAT(refused("slope_azimuth_deg", 361.0), HasSubstr("ground.slope_azimuth_deg: must be within +-360"));
  EXPECT_THAT(refused("slope_degs", 5.0), HasSubstr("ground.slope_degs: unknown field"));
  EXPECT_THAT(refused("rough", 0.05), HasSubstr("ground.rough: must be an object"));
  const auto rough_refused = [](json rough) {
    json doc = paper_json();
    doc["ground"]["rough"] = std::move(rough);
    return error_of(doc);
  };
  const json ok = {{"bump_height_m", 0.05}, {"bump_spacing_m", 0.5}, {"seed", 1}};
  json r = ok;
  r.erase("bump_spacing_m");
  EXPECT_THAT(rough_refused(r), HasSubstr("ground.rough.bump_spacing_m: missing"));
  r = ok;
  r["bump_spacing_m"] = 0.05;
  EXPECT_THAT(rough_refused(r), HasSubstr("ground.rough.bump_spacing_m: must be within [0.1, 100] m"));
  r = ok;
  r["bump_height_m"] = 0.3;
  EXPECT_THAT(rough_refused(r), HasSubstr("ground.rough.bump_height_m: must be at most half of bump_spacing_m"));
  r = ok;
  r["bump_height_m"] = -0.01;
  EXPECT_THAT(rough_refused(r), HasSubstr("ground.rough.bump_height_m: must be >= 0"));
  r = ok;
  r["seed"] = -1;
  EXPECT_THAT(rough_refused(r), HasSubstr("ground.rough.seed: must be a count"));
  r = ok;
  r["seed"] = 1.5;
  EXPECT_THAT(rough_refused(r), HasSubstr("ground.rough.seed: must be a count"));
  r = ok;
  r["seed"] = 9007199254740992ULL;
  EXPECT_THAT(rough_refused(r), HasSubstr("ground.rough.seed: must be below 2^53"));
  r = ok;
  r["bumps"] = 3;
  EXPECT_THAT(rough_refused(r), HasSubstr("ground.rough.bumps: unknown field"));
  r = ok;
  r.erase("seed");
  EXPECT_THAT(rough_refused(r), HasSubstr("ground.rough.seed: missing"));
}

TEST(GroundFields, BulletTakesASlopeButRefusesRoughGround) {
  json doc = paper_json();
  doc["engine"] = "bullet";
  doc["ground"]["slope_deg"] = 5.0;
  EXPECT_EQ(error_of(doc), "");
  doc["ground"]["rough"] = {{"bump_height_m", 0.05}, {"bump_spacing_m", 0.5}, {"seed", 1}};
  EXPECT_THAT(error_of(doc), HasSubstr("ground.rough: the bullet engine has no rough ground"));
}

}  // namespace
}  // namespace tensegrity::sim
