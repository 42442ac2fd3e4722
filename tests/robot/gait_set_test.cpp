// SPDX-License-Identifier: Apache-2.0
// The gait set file: what is written reads back, and each bad field is named.
#include "robot/gait_set.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>

#include "robot/symmetry.hpp"

namespace tensegrity::sim {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

class GaitSetFile : public ::testing::Test {
 protected:
  Robot robot = load_robot(default_robot_path());
  Policy policy =
      load_policy(default_robot_path().parent_path().parent_path() / "policies" / "superball-paper-t4-n5.json", robot);

  json good() const {
    const auto group = symmetry_group(robot);
    GaitSet set{robot.name, robot.hash, "policies/superball-paper-t4-n5.json", 60.0, {}};
    set.gaits.push_back({"(x, y, z)", "(x, y, z)", {0, 4, 10}, -124.0, 33.7, "measured", policy});
    set.gaits.push_back({"(-x, y, z)",
                         "(-x, y, z)",
                         {2, 4, 11},
                         33.4,
                         33.7,
                         "symmetry",
                         image_of(policy, find_symmetry(group, "(-x, y, z)"), robot)});
    return json::parse(gait_set_to_json(set));
  }
  std::string error_of(const json& doc) const {
    try {
      parse_gait_set(doc.dump(), robot, "set.json");
    } catch (const GaitSetError& e) {
      return e.what();
    }
    return "";
  }
};

TEST_F(GaitSetFile, RoundTrips) {
  const GaitSet set = parse_gait_set(good().dump(), robot);
  ASSERT_EQ(set.gaits.size(), 2u);
  EXPECT_EQ(set.gaits[1].face, (std::array<int, 3>{2, 4, 11}));
  EXPECT_EQ(set.gaits[1].heading_deg, 33.4);
  EXPECT_EQ(set.gaits[1].basis, "symmetry");
  EXPECT_EQ(set.gaits[1].policy.provenance.symmetry, "(-x, y, z)");
  EXPECT_EQ(set.gaits[0].policy.cables[7].rest_lengths_m, policy.cables[7].rest_lengths_m);
  const auto path = std::filesystem::path(::testing::TempDir()) / "gait_set_roundtrip.json";
  save_gait_set(path, set);
  EXPECT_EQ(load_gait_set(path, robot).gaits[1].name, "(-x, y, z)");
  std::filesystem::remove(path);
  // The face may be listed in any order.
  json doc = good();
  doc["gaits"][1]["face"] = {11, 2, 4};
  EXPECT_EQ(parse_gait_set(doc.dump(), robot).gaits[1].face, (std::array<int, 3>{2, 4, 11}));
}

TEST_F(GaitSetFile, EachBadFieldIsNamed) {
  struct Case {
    std::function<void(json&)> spoil;
    std::string error;
  };
  const std::vector<Case> cases = {
      {[](json& d) { d["format"] = "tensegrity-gait-set/2"; }, "set.json: format: expected"},
      {[](json& d) { d["robot"] = "superball"; }, "set.json: robot: the set is for robot \"superball\""},
      {[](json& d) { d.erase("duration_s"); }, "set.json: duration_s: missing"},
      {[](json& d) { d["gaits"] = json::array(); }, "set.json: gaits: must hold at least one gait"},
      {[](json& d) { d["colour"] = "red"; }, "set.json: colour: unknown field"},
      {[](json& d) { d["gaits"][1]["name"] = "(x, y, z)"; }, "gaits[1].name: \"(x, y, z)\" appears twice"},
      {[](json& d) {
         d["gaits"][0]["face"] = {0, 4};
       },
       "gaits[0].face: must hold the 3 end caps"},
      {[](json& d) {
         d["gaits"][0]["face"] = {0, 4, 12};
       },
       "gaits[0].face[2]: no such end cap"},
      {[](json& d) {
         d["gaits"][0]["face"] = {0, 1, 2};
       },
       "gaits[0].face: end caps 0, 1, 2 are not a face"},
      {[](json& d) { d["gaits"][1]["heading_deg"] = -180.0; }, "gaits[1].heading_deg: must be within (-180, 180]"},
      {[](json& d) { d["gaits"][1]["speed_m_per_min"] = -1.0; }, "gaits[1].speed_m_per_min: must be >= 0"},
      {[](json& d) { d["gaits"][1].erase("basis"); }, "gaits[1].basis: missing"},
      {[](json& d) { d["gaits"][1]["basis"] = "guessed"; }, "gaits[1].basis: must be \"measured\" or \"symmetry\""},
      {[](json& d) { d["gaits"][1]["policy"] = 3; }, "gaits[1].policy: must be a policy object"},
      {[](json& d) { d["gaits"][1]["policy"]["cables"][5]["rest_lengths_m"][0] = 3.0; },
       "set.json: gaits[1].policy: cables[5].rest_lengths_m[0]: 3 m is outside the rest-length limits"},
      {[](json& d) { d["gaits"][1]["policy"]["cables"][5]["owner"] = 0; }, "gaits[1].policy: cables[5].owner"},
  };
  for (const Case& c : cases) {
    json doc = good();
    c.spoil(doc);
    EXPECT_THAT(error_of(doc), HasSubstr(c.error));
  }
  EXPECT_THAT(error_of(json::parse("[1]")), HasSubstr("set.json: (top level): must be an object"));
  try {
    parse_gait_set("{", robot, "set.json");
    ADD_FAILURE() << "bad JSON accepted";
  } catch (const GaitSetError& e) {
    EXPECT_THAT(e.what(), HasSubstr("set.json: not valid JSON"));
  }
}

}  // namespace
}  // namespace tensegrity::sim
