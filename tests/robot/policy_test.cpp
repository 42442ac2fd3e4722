// SPDX-License-Identifier: Apache-2.0
#include "robot/policy.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

namespace tensegrity::sim {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

class PolicyFile : public ::testing::Test {
 protected:
  Robot robot = load_robot(robot_path_named("superball"));

  json good() const {
    Policy p;
    p.robot = robot.name;
    p.period_s = 4.0;
    p.complexity = 5;
    for (int m = 0; m < 24; ++m) {
      p.cables.push_back({m, robot.cables[m].owner, {0.7, 0.8, 0.9, 1.0, 1.1}});
    }
    p.provenance = {"historical", 7, 5000, 33.5, robot.hash, "test"};
    return json::parse(policy_to_json(p));
  }
  std::string error_of(const json& doc) const {
    try {
      parse_policy(doc.dump(), robot, "p.json");
    } catch (const PolicyError& e) {
      return e.what();
    }
    return "";
  }
};

TEST_F(PolicyFile, RoundTrips) {
  const Policy p = parse_policy(good().dump(), robot);
  EXPECT_EQ(p.complexity, 5);
  EXPECT_EQ(p.period_s, 4.0);
  EXPECT_EQ(p.cables[13].owner, 3);
  EXPECT_EQ(p.cables[13].rest_lengths_m[2], 0.9);
  EXPECT_EQ(p.provenance.seed, 7U);
  EXPECT_EQ(p.provenance.robot_hash, robot.hash);
  const auto path = std::filesystem::path(::testing::TempDir()) / "policy_roundtrip.json";
  save_policy(path, p);
  const Policy q = load_policy(path, robot);
  EXPECT_EQ(q.cables[23].rest_lengths_m, p.cables[23].rest_lengths_m);
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".tmp"));
  std::filesystem::remove(path);
}

// The heading a gait rolls, in its start frame: absent is unknown, present is checked.
TEST_F(PolicyFile, HeadingIsOptionalAndChecked) {
  json doc = good();
  EXPECT_FALSE(parse_policy(doc.dump(), robot).provenance.heading_deg.has_value());
  doc["provenance"]["gait"] = {
      {"axial_spin_rms_rad_per_s", 0.5}, {"axial_spin_max_rad_per_s", 2.0}, {"endcaps_touched_ground", 12}};
  EXPECT_FALSE(parse_policy(doc.dump(), robot).provenance.heading_deg.has_value());
  doc["provenance"]["gait"]["heading_deg"] = -124.0;
  const Policy p = parse_policy(doc.dump(), robot);
  ASSERT_TRUE(p.provenance.heading_deg.has_value());
  EXPECT_EQ(*p.provenance.heading_deg, -124.0);
  EXPECT_EQ(json::parse(policy_to_json(p))["provenance"]["gait"]["heading_deg"], -124.0);
  doc["provenance"]["gait"]["heading_deg"] = 180.5;
  EXPECT_THAT(error_of(doc), HasSubstr("p.json: provenance.gait.heading_deg: must be within (-180, 180]"));
  doc["provenance"]["gait"]["heading_deg"] = "north";
  EXPECT_THAT(error_of(doc), HasSubstr("provenance.gait.heading_deg: must be a number"));
  doc["provenance"]["gait"].erase("heading_deg");
  doc["provenance"]["symmetry"] = 3;
  EXPECT_THAT(error_of(doc), HasSubstr("provenance.symmetry: must be a non-empty string"));
}

TEST_F(PolicyFile, EndcapTableHoldsTheOwnedCablesInOrder) {
  json doc = good();
  doc["cables"][9]["rest_lengths_m"][0] = 0.61;   // cable 9 is end cap 2's first
  doc["cables"][10]["rest_lengths_m"][0] = 0.62;  // cable 10 its second
  const Policy p = parse_policy(doc.dump(), robot);
  const auto table = endcap_table(p, robot, 2);
  EXPECT_EQ(table.motor_count, 2U);
  EXPECT_EQ(table.complexity, 5U);
  EXPECT_EQ(table.rest_length_m[0][0], 0.61);
  EXPECT_EQ(table.rest_length_m[1][0], 0.62);
}

TEST_F(PolicyFile, EachBadFieldIsNamed) {
  json doc = good();
  doc["format"] = "tensegrity-policy/2";
  EXPECT_THAT(error_of(doc), HasSubstr("p.json: format"));
  doc = good();
  doc["robot"] = "ballerina";
  EXPECT_THAT(error_of(doc), HasSubstr("robot: policy is for robot \"ballerina\""));
  doc = good();
  doc["period_s"] = 0.0;
  EXPECT_THAT(error_of(doc), HasSubstr("period_s: must be within (0, 3600]"));
  doc = good();
  doc["period_s"] = -4.0;
  EXPECT_THAT(error_of(doc), HasSubstr("period_s"));
  doc = good();
  doc["complexity"] = 0;
  EXPECT_THAT(error_of(doc), HasSubstr("complexity: must be 1..16"));
  doc = good();
  doc["cables"].erase(5);
  EXPECT_THAT(error_of(doc), HasSubstr("cables: has 23 entries, the robot has 24 cables"));
  doc = good();
  doc["cables"][4]["rest_lengths_m"].erase(1);
  EXPECT_THAT(error_of(doc), HasSubstr("cables[4].rest_lengths_m: must hold exactly 5 values"));
  doc = good();
  doc["cables"][6]["rest_lengths_m"][3] = 1.2;
  EXPECT_THAT(error_of(doc), HasSubstr("cables[6].rest_lengths_m[3]: 1.2 m is outside the rest-length limits"));
  doc = good();
  doc["cables"][6]["rest_lengths_m"][3] = "0.9";
  EXPECT_THAT(error_of(doc), HasSubstr("cables[6].rest_lengths_m[3]: must be a number"));
  doc = good();
  doc["cables"][1]["owner"] = 0;  // cable 1 (0-5) is end cap 5's
  EXPECT_THAT(error_of(doc), HasSubstr("cables[1].owner: cable 1 is owned by end cap 5, not 0"));
  doc = good();
  doc["cables"][2]["cable"] = 1;
  EXPECT_THAT(error_of(doc), HasSubstr("cables[2].cable: cable 1 appears twice"));
  doc = good();
  doc["cables"][2]["cable"] = 24;
  EXPECT_THAT(error_of(doc), HasSubstr("cables[2].cable: no such cable"));
}

TEST_F(PolicyFile, ProvenanceKeepsTheMutationScheduleAndChecksIt) {
  EXPECT_FALSE(good()["provenance"].contains("mutation")) << "not recorded: not written";
  Policy p = parse_policy(good().dump(), robot);
  p.provenance.sigma_m = 0.05;
  p.provenance.sigma_final_m = 0.01;
  p.provenance.anneal_episodes = 2500;
  const json doc = json::parse(policy_to_json(p));
  const Policy q = parse_policy(doc.dump(), robot);
  EXPECT_EQ(q.provenance.sigma_m, 0.05);
  EXPECT_EQ(q.provenance.sigma_final_m, 0.01);
  EXPECT_EQ(q.provenance.anneal_episodes, 2500);
  json bad = doc;
  bad["provenance"]["mutation"]["anneal_episodes"] = -3;
  EXPECT_THAT(error_of(bad), HasSubstr("provenance.mutation: steps and anneal_episodes must be >= 0"));
  bad = doc;
  bad["provenance"]["mutation"].erase("sigma_final_m");
  EXPECT_THAT(error_of(bad), HasSubstr("provenance.mutation.sigma_final_m: must be a number"));
  bad = doc;
  bad["provenance"]["mutation"] = 0.05;
  EXPECT_THAT(error_of(bad), HasSubstr("provenance.mutation: must be an object"));
}

TEST_F(PolicyFile, ProvenanceKeepsThePopulationSizesAndChecksThem) {
  EXPECT_FALSE(good()["provenance"].contains("population")) << "not recorded: not written";
  EXPECT_EQ(parse_policy(good().dump(), robot).provenance.population, 0);
  Policy p = parse_policy(good().dump(), robot);
  p.provenance.population = 40;
  p.provenance.replace = 20;
  p.provenance.teams = 50;
  const json doc = json::parse(policy_to_json(p));
  const Policy q = parse_policy(doc.dump(), robot);
  EXPECT_EQ(q.provenance.population, 40);
  EXPECT_EQ(q.provenance.replace, 20);
  EXPECT_EQ(q.provenance.teams, 50);
  json bad = doc;
  bad["provenance"].erase("teams");
  EXPECT_THAT(error_of(bad), HasSubstr("provenance.population: population, replace and teams go together"));
  bad = doc;
  bad["provenance"]["replace"] = 21;
  EXPECT_THAT(error_of(bad), HasSubstr("provenance.replace: must be within 1..population/2"));
  bad = doc;
  bad["provenance"]["population"] = 1;
  EXPECT_THAT(error_of(bad), HasSubstr("provenance.population: must be within 2..100000"));
  bad = doc;
  bad["provenance"]["teams"] = 2.5;
  EXPECT_THAT(error_of(bad), HasSubstr("provenance.teams: must be an integer"));
}

TEST_F(PolicyFile, ProvenanceKeepsTheGaitsStrutGapsAndChecksThem) {
  Policy p = parse_policy(good().dump(), robot, "p.json");
  p.provenance.axial_spin_rms_rad_per_s = 0.5;
  p.provenance.endcaps_touched_ground = 12;
  const json without = json::parse(policy_to_json(p));
  EXPECT_FALSE(without["provenance"]["gait"].contains("min_strut_gap_m")) << "not recorded: not written";
  EXPECT_FALSE(parse_policy(without.dump(), robot, "p.json").provenance.min_strut_gap_m.has_value());
  p.provenance.min_strut_gap_m = -0.012;
  p.provenance.strut_overlap_s = 1.5;
  const Policy q = parse_policy(policy_to_json(p), robot, "p.json");
  EXPECT_EQ(q.provenance.min_strut_gap_m, -0.012);
  EXPECT_EQ(q.provenance.strut_overlap_s, 1.5);
  json bad = json::parse(policy_to_json(p));
  bad["provenance"]["gait"]["strut_overlap_s"] = -1.0;
  EXPECT_THAT(error_of(bad), HasSubstr("provenance.gait.strut_overlap_s: must be >= 0"));
  bad["provenance"]["gait"]["min_strut_gap_m"] = "close";
  EXPECT_THAT(error_of(bad), HasSubstr("provenance.gait.min_strut_gap_m: must be a number"));
}

TEST_F(PolicyFile, NonFiniteValueIsNamed) {
  // JSON has no NaN; an overflowing literal is how a non-finite number arrives.
  std::string text = good().dump();
  const auto at = text.find("1.1");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 3, "1e999");
  try {
    parse_policy(text, robot, "p.json");
    FAIL();
  } catch (const PolicyError& e) {
    EXPECT_THAT(e.what(), HasSubstr("p.json: not valid JSON"));
    EXPECT_THAT(e.what(), HasSubstr("1e999"));
  }
}

TEST_F(PolicyFile, MissingFileIsAClearError) {
  EXPECT_THROW(load_policy("/nonexistent/policy.json", robot), PolicyError);
}

TEST_F(PolicyFile, NamesItsRobotSoNoRobotNeedBeGiven) {
  const auto dir = std::filesystem::temp_directory_path() / ("policy_robot_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& name, const json& doc) {
    const auto path = dir / name;
    std::ofstream(path) << doc.dump();
    return path;
  };
  json doc = good();
  doc["robot"] = "superball-ntrt2014";
  EXPECT_EQ(robot_path_for_policy(write("ntrt.json", doc)).filename(), "superball-ntrt2014.json");
  EXPECT_EQ(load_robot(robot_path_for_policy(dir / "ntrt.json")).name, "superball-ntrt2014");
  // Unknown robots, paths smuggled in as names and broken files fall back to the
  // default robot, whose own name check then reports the mismatch.
  doc["robot"] = "no-such-robot";
  EXPECT_EQ(robot_path_for_policy(write("unknown.json", doc)), default_robot_path());
  doc["robot"] = "../robots/superball-ntrt2014";
  EXPECT_EQ(robot_path_for_policy(write("path.json", doc)), default_robot_path());
  std::ofstream(dir / "broken.json") << "{";
  EXPECT_EQ(robot_path_for_policy(dir / "broken.json"), default_robot_path());
  EXPECT_EQ(robot_path_for_policy(dir / "missing.json"), default_robot_path());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace tensegrity::sim
