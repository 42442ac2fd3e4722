// SPDX-License-Identifier: Apache-2.0
#include "robot/robot.hpp"
#include "tests/robot/robot_json.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace tensegrity::sim {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

json superball_json() { return test_files::shipped_robot_json("superball"); }

std::string error_of(const json& doc) { return test_files::robot_error_of(doc); }

TEST(Robot, ShippedSuperballLoads) {
  const Robot robot = load_robot(robot_path_named("superball"));
  EXPECT_EQ(robot.name, "superball");
  EXPECT_EQ(robot.node_count(), 12);
  EXPECT_EQ(robot.struts.size(), 6U);
  EXPECT_EQ(robot.cable_count(), 24);
  EXPECT_EQ(robot.hash.size(), 16U);
  for (int e = 0; e < 12; ++e) EXPECT_EQ(robot.cables_of(e).size(), 2U) << "end cap " << e;
  // All 24 cables of Fuller's expanded octahedron are the same length.
  for (const auto& c : robot.cables) {
    EXPECT_NEAR((robot.nodes_m[c.node_a] - robot.nodes_m[c.node_b]).norm(), 1.0408, 1e-3);
  }
}

// The default is the paper's simulated SUPERball (1.5 m rods, the author's anchors and
// rod contact, the hardware's cables), not the 1.7 m hardware (docs/design/robot.md).
TEST(Robot, TheDefaultIsThePapersSimulatedSuperball) {
  const Robot robot = load_robot(default_robot_path());
  EXPECT_EQ(robot.name, "superball-paper");
  const auto& s = robot.struts[0];
  EXPECT_NEAR((robot.nodes_m[s.node_a] - robot.nodes_m[s.node_b]).norm(), 1.5, 1e-9);
  EXPECT_EQ(robot.cable_attachment, CableAttachment::surface);
  EXPECT_TRUE(robot.rod_contact);
  EXPECT_DOUBLE_EQ(robot.cables[0].stiffness_n_per_m, 1000.0);
  EXPECT_DOUBLE_EQ(robot.cables[0].damping_n_s_per_m, 50.0);
  EXPECT_NE(robot.hash, load_robot(robot_path_named("superball")).hash);
}

TEST(Robot, HashChangesWithContent) {
  json doc = superball_json();
  const Robot a = parse_robot(doc.dump());
  doc["cable"]["stiffness_n_per_m"] = 1001.0;
  const Robot b = parse_robot(doc.dump());
  EXPECT_NE(a.hash, b.hash);
}

// The description is prose for readers; rewording it must not orphan the policies
// and checkpoints that record the robot's hash.
TEST(Robot, HashIgnoresTheDescription) {
  json doc = superball_json();
  const Robot a = parse_robot(doc.dump());
  doc["description"] = "reworded";
  const Robot b = parse_robot(doc.dump());
  doc.erase("description");
  const Robot c = parse_robot(doc.dump());
  EXPECT_EQ(a.hash, b.hash);
  EXPECT_EQ(a.hash, c.hash);
}

TEST(Robot, MissingCableEndNamed) {
  json doc = superball_json();
  doc["cables"][3]["nodes"] = json::array({0});
  EXPECT_THAT(error_of(doc), HasSubstr("test.json: cables[3].nodes: must be a pair"));
  doc = superball_json();
  doc["cables"][5]["nodes"][1] = 12;
  EXPECT_THAT(error_of(doc), HasSubstr("cables[5].nodes[1]: node 12 does not exist"));
  doc = superball_json();
  doc["cables"][2].erase("nodes");
  EXPECT_THAT(error_of(doc), HasSubstr("cables[2].nodes: missing"));
}

TEST(Robot, NonFiniteNumberNamed) {
  json doc = superball_json();
  doc["nodes_m"][4][2] = "nan";
  EXPECT_THAT(error_of(doc), HasSubstr("nodes_m[4][2]: must be a number"));
  // JSON has no NaN literal; a huge exponent parses to infinity.
  std::string text = superball_json().dump();
  const auto at = text.find("\"mass_kg\":3.5");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 13, "\"mass_kg\":1e999");
  try {
    parse_robot(text, "test.json");
    FAIL() << "infinite mass accepted";
  } catch (const RobotError& e) {
    EXPECT_THAT(e.what(), HasSubstr("test.json: not valid JSON"));
    EXPECT_THAT(e.what(), HasSubstr("1e999"));
  }
}

TEST(Robot, NegativeMassNamed) {
  json doc = superball_json();
  doc["strut"]["mass_kg"] = -3.5;
  EXPECT_THAT(error_of(doc), HasSubstr("strut.mass_kg: must be > 0"));
}

TEST(Robot, CableAlongOneStrutNamed) {
  json doc = superball_json();
  doc["cables"][7]["nodes"] = json::array({0, 1});  // struts[0] is 0-1
  doc["cables"][7]["owner"] = 0;
  EXPECT_THAT(error_of(doc), HasSubstr("cables[7].nodes: both ends are on struts[0]"));
}

TEST(Robot, AbsurdGeometryNamed) {
  json doc = superball_json();
  doc["nodes_m"][3][1] = 1e308;
  EXPECT_THAT(error_of(doc), HasSubstr("nodes_m[3][1]: must be within +-100 m of the origin"));
  doc = superball_json();
  doc["nodes_m"][5][0] = 1e6;  // a thousand kilometres away
  EXPECT_THAT(error_of(doc), HasSubstr("nodes_m[5][0]: must be within +-100 m"));
  doc = superball_json();
  doc["nodes_m"][0] = json::array({-40.0, 0.0, 0.0});
  doc["nodes_m"][1] = json::array({40.0, 0.0, 0.0});  // struts[0] joins nodes 0 and 1
  EXPECT_THAT(error_of(doc), HasSubstr("strut is longer than 20 m"));
  doc = superball_json();
  doc["strut"]["mass_kg"] = 1e9;
  EXPECT_THAT(error_of(doc), HasSubstr("strut.mass_kg: must be at most 1000 kg"));
  doc = superball_json();
  doc["strut"]["radius_m"] = 5.0;
  EXPECT_THAT(error_of(doc), HasSubstr("strut.radius_m: must be at most 1 m"));
}

TEST(Robot, OwnerNotAnEndNamed) {
  json doc = superball_json();
  doc["cables"][0]["owner"] = 7;  // cable 0 joins 0 and 4
  EXPECT_THAT(error_of(doc), HasSubstr("cables[0].owner: end cap 7 is not an end of this cable"));
}

TEST(Robot, OtherBadFieldsNamed) {
  json doc = superball_json();
  doc["format"] = "tensegrity-robot/9";
  EXPECT_THAT(error_of(doc), HasSubstr("format: expected"));
  doc = superball_json();
  doc["cable"]["max_rest_length_m"] = 0.5;
  EXPECT_THAT(error_of(doc), HasSubstr("cable.max_rest_length_m: must be above min_rest_length_m"));
  doc = superball_json();
  doc["cable"]["hard_limit_tension_n"] = 300.0;
  EXPECT_THAT(error_of(doc), HasSubstr("cable.hard_limit_tension_n"));
  doc = superball_json();
  doc["struts"][1] = json::array({0, 3});
  EXPECT_THAT(error_of(doc), HasSubstr("struts[1]: node 0 is already an end of struts[0]"));
  doc = superball_json();
  doc["time_step_s"] = 0.0;
  EXPECT_THAT(error_of(doc), HasSubstr("time_step_s: must be > 0"));
  doc = superball_json();
  doc["ground"]["friction"] = -1;
  EXPECT_THAT(error_of(doc), HasSubstr("ground.friction: must be >= 0"));
  doc = superball_json();
  doc["cables"][4]["nodes"] = doc["cables"][3]["nodes"];
  doc["cables"][4]["owner"] = doc["cables"][3]["owner"];
  EXPECT_THAT(error_of(doc), HasSubstr("cables[4].nodes: duplicate cable"));
  EXPECT_THAT(error_of(json::parse("[1,2]")), HasSubstr("must be an object"));
  try {
    parse_robot("{not json", "broken.json");
    FAIL();
  } catch (const RobotError& e) {
    EXPECT_THAT(e.what(), HasSubstr("broken.json: not valid JSON"));
  }
}

TEST(Robot, SpinFieldsAreOptionalAndValidated) {
  json doc = superball_json();
  const Robot plain = parse_robot(doc.dump(), "test.json");
  EXPECT_EQ(plain.cable_attachment, CableAttachment::axis);
  doc["strut"]["cable_attachment"] = "surface";
  const Robot spun = parse_robot(doc.dump(), "test.json");
  EXPECT_EQ(spun.cable_attachment, CableAttachment::surface);
  EXPECT_NE(spun.hash, plain.hash);
  doc["strut"]["cable_attachment"] = "rim";
  EXPECT_THAT(error_of(doc), HasSubstr("test.json: strut.cable_attachment: must be \"axis\" or \"surface\""));
  doc["strut"]["cable_attachment"] = 1;
  EXPECT_THAT(error_of(doc), HasSubstr("strut.cable_attachment: must be a string"));
  doc["strut"]["cable_attachment"] = "axis";
  EXPECT_EQ(parse_robot(doc.dump(), "test.json").cable_attachment, CableAttachment::axis);
}

TEST(Robot, RodContactIsOptionalAndValidated) {
  json doc = superball_json();
  const Robot plain = parse_robot(doc.dump(), "test.json");
  EXPECT_FALSE(plain.rod_contact);
  doc["strut"]["rod_contact"] = true;
  const Robot colliding = parse_robot(doc.dump(), "test.json");
  EXPECT_TRUE(colliding.rod_contact);
  EXPECT_NE(colliding.hash, plain.hash);
  doc["strut"]["rod_contact"] = "yes";
  EXPECT_THAT(error_of(doc), HasSubstr("test.json: strut.rod_contact: must be true or false"));
  doc["strut"]["rod_contact"] = 1;
  EXPECT_THAT(error_of(doc), HasSubstr("strut.rod_contact: must be true or false"));
}

TEST(Robot, StartPoseIsOptionalAndValidated) {
  json doc = superball_json();
  const Robot plain = parse_robot(doc.dump(), "test.json");
  EXPECT_EQ(plain.start_pose, Robot::StartPose::face_down);
  doc["start"]["pose"] = "description";
  const Robot described = parse_robot(doc.dump(), "test.json");
  EXPECT_EQ(described.start_pose, Robot::StartPose::description);
  EXPECT_NE(described.hash, plain.hash);
  doc["start"]["pose"] = "upright";
  EXPECT_THAT(error_of(doc), HasSubstr("test.json: start.pose: must be \"face_down\" or \"description\""));
}

TEST(Robot, OverloadIsOptionalAndValidated) {
  json doc = superball_json();
  const Robot plain = parse_robot(doc.dump(), "test.json");
  EXPECT_EQ(plain.motor.overload, core::Overload::hold);
  doc["cable"]["overload"] = "pay_out";
  const Robot yielding = parse_robot(doc.dump(), "test.json");
  EXPECT_EQ(yielding.motor.overload, core::Overload::pay_out);
  EXPECT_NE(yielding.hash, plain.hash);
  doc["cable"]["overload"] = "slip";
  EXPECT_THAT(error_of(doc), HasSubstr("test.json: cable.overload: must be \"hold\" or \"pay_out\" (got \"slip\")"));
  doc["cable"]["overload"] = 1;
  EXPECT_THAT(error_of(doc), HasSubstr("test.json: cable.overload: must be a string"));
}

TEST(Robot, DampingLawIsOptionalAndValidated) {
  json doc = superball_json();
  const Robot plain = parse_robot(doc.dump(), "test.json");
  EXPECT_FALSE(plain.cable_damping_capped);
  doc["cable"]["damping_law"] = "capped";
  const Robot capped = parse_robot(doc.dump(), "test.json");
  EXPECT_TRUE(capped.cable_damping_capped);
  EXPECT_NE(capped.hash, plain.hash);
  doc["cable"]["damping_law"] = "linear";
  EXPECT_FALSE(parse_robot(doc.dump(), "test.json").cable_damping_capped);
  doc["cable"]["damping_law"] = "clipped";
  EXPECT_THAT(error_of(doc),
              HasSubstr("test.json: cable.damping_law: must be \"linear\" or \"capped\" (got \"clipped\")"));
  doc["cable"]["damping_law"] = 0;
  EXPECT_THAT(error_of(doc), HasSubstr("test.json: cable.damping_law: must be a string"));
}

TEST(Robot, EngineAndAxialSpinAreOptionalAndValidated) {
  json doc = superball_json();
  const Robot plain = parse_robot(doc.dump(), "test.json");
  EXPECT_EQ(plain.engine, Robot::PhysicsEngine::ode);
  EXPECT_FALSE(plain.zero_axial_spin);
  doc["engine"] = "bullet";
  doc["strut"]["axial_spin"] = "zeroed";
  const Robot bullet = parse_robot(doc.dump(), "test.json");
  EXPECT_EQ(bullet.engine, Robot::PhysicsEngine::bullet);
  EXPECT_TRUE(bullet.zero_axial_spin);
  EXPECT_NE(bullet.hash, plain.hash);
  doc["strut"]["axial_spin"] = "free";
  EXPECT_FALSE(parse_robot(doc.dump(), "test.json").zero_axial_spin);
  doc["strut"]["axial_spin"] = "locked";
  EXPECT_THAT(error_of(doc), HasSubstr("test.json: strut.axial_spin: must be \"free\" or \"zeroed\" (got \"locked\")"));
  doc["strut"]["axial_spin"] = "free";
  doc["strut"]["axial_damping_n_m_s"] = 1e307;
  EXPECT_THAT(error_of(doc), HasSubstr("test.json: strut.axial_damping_n_m_s: must be at most 100 N m s"));
  doc["strut"]["axial_damping_n_m_s"] = 0.005;
  doc["gravity_m_per_s2"] = 1e308;
  EXPECT_THAT(error_of(doc), HasSubstr("test.json: gravity_m_per_s2: must be at most 250 m/s^2"));
  doc["gravity_m_per_s2"] = 9.81;
  doc["engine"] = "physx";
  EXPECT_THAT(error_of(doc), HasSubstr("test.json: engine: must be \"ode\" or \"bullet\""));
  doc["engine"] = 2;
  EXPECT_THAT(error_of(doc), HasSubstr("test.json: engine: must be a string"));
}

TEST(Robot, MissingFileIsAClearError) {
  try {
    load_robot("/nonexistent/robot.json");
    FAIL();
  } catch (const RobotError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/robot.json: cannot open"));
  }
}

}  // namespace
}  // namespace tensegrity::sim
