// SPDX-License-Identifier: Apache-2.0
#include "robot/robot.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "format/json_reader.hpp"

namespace tensegrity::sim {
namespace {

using nlohmann::json;
using Reader = format::JsonReader<RobotError>;

// Bounds of plausible geometry: past them ODE aborts or the model runs with tensions
// of 1e9 N (a node at 1e308 m, or a thousand kilometres away, was accepted before).
// Generous on purpose: SUPERball's struts are 1.5-1.7 m and 2-4 kg.
constexpr double kMaxCoordinateM = 100.0;
constexpr double kMaxStrutLengthM = 20.0;
constexpr double kMaxStrutMassKg = 1000.0;
constexpr double kMaxStrutRadiusM = 1.0;
// SUPERball's stand-ins are 0.005-0.5 N m s; 1e307 made ODE abort mid-step (fuzzing).
constexpr double kMaxAxialDampingNms = 100.0;
// Steeper than 45 degrees, a robot of friction 1 slides whatever it does.
constexpr double kMaxSlopeDeg = 45.0;
constexpr double kMinBumpSpacingM = 0.1;
constexpr double kMaxBumpSpacingM = 100.0;
constexpr std::uint64_t kMaxSeed = (std::uint64_t{1} << 53) - 1;

int node_index(const Reader& r, const json& v, const std::string& path, int node_count) {
  if (!v.is_number_integer()) r.fail_at(path, "must be a node index (integer)");
  const auto i = v.get<long long>();
  if (i < 0 || i >= node_count) {
    r.fail_at(path, "node " + std::to_string(i) + " does not exist (" + std::to_string(node_count) + " nodes)");
  }
  return static_cast<int>(i);
}

void check_pair(const Reader& r, const json& pair, const std::string& path, int node_count, int& a, int& b) {
  if (!pair.is_array() || pair.size() != 2) r.fail_at(path, "must be a pair of node indices");
  a = node_index(r, pair[0], path + "[0]", node_count);
  b = node_index(r, pair[1], path + "[1]", node_count);
  if (a == b) r.fail_at(path, "both ends are node " + std::to_string(a));
}

void parse_nodes(const Reader& r, Robot& robot) {
  const json& nodes = r.array("nodes_m");
  if (nodes.size() < 4) r.fail("nodes_m", "needs at least 4 nodes");
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const std::string path = "nodes_m[" + std::to_string(i) + "]";
    if (!nodes[i].is_array() || nodes[i].size() != 3) r.fail_at(path, "must be [x, y, z]");
    Eigen::Vector3d p;
    for (int k = 0; k < 3; ++k) {
      const std::string coordinate = path + "[" + std::to_string(k) + "]";
      p[k] = r.number_at(nodes[i][k], coordinate);
      if (std::abs(p[k]) > kMaxCoordinateM) r.fail_at(coordinate, "must be within +-100 m of the origin");
    }
    robot.nodes_m.push_back(p);
  }
}

// The fields that decide how struts turn about their own axes and whether they
// collide (docs/design/model.md) are optional, so that older robot files keep their behaviour.
void parse_strut(const Reader& r, Robot& robot) {
  const Reader strut = r.object("strut");
  robot.strut_mass_kg = strut.positive("mass_kg", 0.0, true);
  robot.strut_radius_m = strut.positive("radius_m", 0.0, true);
  if (robot.strut_mass_kg > kMaxStrutMassKg) strut.fail("mass_kg", "must be at most 1000 kg");
  if (robot.strut_radius_m > kMaxStrutRadiusM) strut.fail("radius_m", "must be at most 1 m");
  robot.axial_damping_n_m_s = strut.non_negative("axial_damping_n_m_s", 0.0);
  if (robot.axial_damping_n_m_s > kMaxAxialDampingNms) strut.fail("axial_damping_n_m_s", "must be at most 100 N m s");
  robot.cable_attachment =
      strut.choice("cable_attachment", {"axis", "surface"}, 0) == 0 ? CableAttachment::axis : CableAttachment::surface;
  robot.zero_axial_spin = strut.choice("axial_spin", {"free", "zeroed"}, 0) == 1;
  robot.rod_contact = strut.boolean("rod_contact", false);
}

// Returns each node's strut.
std::vector<int> parse_struts(const Reader& r, Robot& robot) {
  const int n = robot.node_count();
  const json& struts = r.array("struts");
  std::vector<int> strut_of(n, -1);
  for (std::size_t i = 0; i < struts.size(); ++i) {
    const std::string path = "struts[" + std::to_string(i) + "]";
    StrutSpec s;
    check_pair(r, struts[i], path, n, s.node_a, s.node_b);
    for (const int node : {s.node_a, s.node_b}) {
      if (strut_of[node] >= 0) {
        r.fail_at(path, "node " + std::to_string(node) + " is already an end of struts[" +
                            std::to_string(strut_of[node]) + "]");
      }
      strut_of[node] = static_cast<int>(i);
    }
    const double length = (robot.nodes_m[s.node_a] - robot.nodes_m[s.node_b]).norm();
    if (length < 4.0 * robot.strut_radius_m) r.fail_at(path, "strut is shorter than four radii");
    if (length > kMaxStrutLengthM) r.fail_at(path, "strut is longer than 20 m");
    robot.struts.push_back(s);
  }
  for (int node = 0; node < n; ++node) {
    if (strut_of[node] < 0) r.fail("struts", "node " + std::to_string(node) + " is the end of no strut");
  }
  return strut_of;
}

void parse_cable_defaults(const Reader& r, Robot& robot) {
  const Reader cable = r.object("cable");
  robot.motor.min_rest_length_m = cable.positive("min_rest_length_m", 0.0, true);
  robot.motor.max_rest_length_m = cable.positive("max_rest_length_m", 0.0, true);
  robot.motor.speed_m_per_s = cable.positive("motor_speed_m_per_s", 0.0, true);
  robot.motor.cutoff_tension_n = cable.positive("cutoff_tension_n", 0.0, true);
  robot.motor.hard_limit_tension_n = cable.positive("hard_limit_tension_n", 0.0, true);
  const auto& names = core::kOverloadNames;
  robot.motor.overload = static_cast<core::Overload>(cable.choice("overload", {names[0], names[1]}, 0));
  // The end cap's own check of its limits (its config is checked by the same).
  if (const core::LimitsError e = core::validate(robot.motor); e != core::LimitsError::none) {
    cable.fail(core::field_of(e), core::describe(e));
  }
  robot.initial_rest_length_m = cable.positive("initial_rest_length_m", 0.0, true);
  if (robot.initial_rest_length_m < robot.motor.min_rest_length_m ||
      robot.initial_rest_length_m > robot.motor.max_rest_length_m) {
    cable.fail("initial_rest_length_m", "must lie within [min_rest_length_m, max_rest_length_m]");
  }
}

void parse_cables(const Reader& r, const std::vector<int>& strut_of, Robot& robot) {
  const Reader defaults = r.object("cable");
  const double k_default = defaults.positive("stiffness_n_per_m", 0.0, true);
  const double c_default = defaults.non_negative("damping_n_s_per_m");
  robot.cable_damping_capped = defaults.choice("damping_law", {"linear", "capped"}, 0) == 1;
  const int n = robot.node_count();
  const json& cables = r.array("cables");
  if (cables.empty()) r.fail("cables", "needs at least one cable");
  std::set<std::pair<int, int>> seen;
  for (std::size_t i = 0; i < cables.size(); ++i) {
    const Reader c = r.element("cables", i);
    CableSpec spec;
    check_pair(r, c.at("nodes"), c.field("nodes"), n, spec.node_a, spec.node_b);
    if (strut_of[spec.node_a] == strut_of[spec.node_b]) {
      c.fail("nodes",
             "both ends are on struts[" + std::to_string(strut_of[spec.node_a]) + "]: a cable must join two struts");
    }
    const auto key = std::minmax(spec.node_a, spec.node_b);
    if (!seen.insert(key).second) c.fail("nodes", "duplicate cable between these nodes");
    spec.owner = node_index(r, c.at("owner"), c.field("owner"), n);
    if (spec.owner != spec.node_a && spec.owner != spec.node_b) {
      c.fail("owner", "end cap " + std::to_string(spec.owner) + " is not an end of this cable");
    }
    spec.stiffness_n_per_m = c.positive("stiffness_n_per_m", k_default);
    spec.damping_n_s_per_m = c.non_negative("damping_n_s_per_m", c_default);
    robot.cables.push_back(spec);
  }
}

// Optional: without them the ground is the plane z = 0, as every robot file before.
void parse_terrain(const Reader& ground, Robot& robot) {
  ground.only({"friction", "restitution", "contact_stiffness_n_per_m", "contact_damping_n_s_per_m", "slope_deg",
               "slope_azimuth_deg", "rough"});
  robot.ground_slope_deg = ground.non_negative("slope_deg", 0.0);
  if (robot.ground_slope_deg > kMaxSlopeDeg) ground.fail("slope_deg", "must be at most 45 degrees");
  robot.ground_slope_azimuth_deg = ground.number("slope_azimuth_deg", 0.0);
  if (std::abs(robot.ground_slope_azimuth_deg) > 360.0) {
    ground.fail("slope_azimuth_deg", "must be within +-360 degrees");
  }
  if (!ground.has("rough")) return;
  const Reader rough = ground.object("rough");
  rough.only({"bump_height_m", "bump_spacing_m", "seed"});
  auto& r = robot.ground_rough;
  r.bump_spacing_m = rough.positive("bump_spacing_m", 0.0, true);
  if (r.bump_spacing_m < kMinBumpSpacingM || r.bump_spacing_m > kMaxBumpSpacingM) {
    rough.fail("bump_spacing_m", "must be within [0.1, 100] m");
  }
  r.bump_height_m = rough.non_negative("bump_height_m");
  // Steeper bumps would break the contact's tangent-plane approximation
  // (sim/model/terrain.hpp): at half the spacing the steepest flank is 37 degrees.
  if (r.bump_height_m > 0.5 * r.bump_spacing_m) rough.fail("bump_height_m", "must be at most half of bump_spacing_m");
  r.seed = rough.count("seed");
  if (r.seed > kMaxSeed) rough.fail("seed", "must be below 2^53 (exact in JSON)");
  if (robot.engine == Robot::PhysicsEngine::bullet && r.bump_height_m > 0.0) {
    ground.fail("rough", "the bullet engine has no rough ground (a slope it has); use \"engine\": \"ode\"");
  }
}

void parse_ground_and_start(const Reader& r, Robot& robot) {
  const Reader ground = r.object("ground");
  robot.ground_friction = ground.non_negative("friction");
  robot.ground_restitution = ground.non_negative("restitution", 0.0);
  if (robot.ground_restitution > 1.0) ground.fail("restitution", "must be within [0, 1]");
  robot.contact_stiffness_n_per_m = ground.positive("contact_stiffness_n_per_m", 0.0, true);
  robot.contact_damping_n_s_per_m = ground.non_negative("contact_damping_n_s_per_m");
  parse_terrain(ground, robot);
  const Reader start = r.object("start");
  robot.start_clearance_m = start.non_negative("clearance_m");
  robot.settle_s = start.non_negative("settle_s");
  robot.start_pose = start.choice("pose", {"face_down", "description"}, 0) == 0 ? Robot::StartPose::face_down
                                                                                : Robot::StartPose::description;
}

// Optional: without it, teams are learned at the robot's own step.
void parse_learning(const Reader& r, Robot& robot) {
  const Reader learning = r.object_or_empty("learning");
  learning.only({"time_step_s", "early_end"});
  robot.learning_time_step_s = learning.positive("time_step_s", robot.time_step_s);
  if (robot.learning_time_step_s > 0.01) {
    learning.fail("time_step_s", "must be at most 0.01 s (the model is unstable above)");
  }
  if (!learning.has("early_end")) return;
  const Reader early = learning.object("early_end");
  early.only({"bar_m", "max_speed_m_per_s"});
  robot.early_end_bar_m = early.positive("bar_m", 0.0, true);
  robot.early_end_max_speed_m_per_s = early.positive("max_speed_m_per_s", 0.0, true);
  if (robot.early_end_bar_m > 1000.0) early.fail("bar_m", "must be at most 1000 m");
  if (robot.early_end_max_speed_m_per_s > 100.0) early.fail("max_speed_m_per_s", "must be at most 100 m/s");
}

}  // namespace

std::string fnv1a64_hex(const std::string& text) {
  std::uint64_t h = 1469598103934665603ULL;
  for (const unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::vector<int> Robot::cables_of(int endcap) const {
  std::vector<int> out;
  for (int m = 0; m < cable_count(); ++m) {
    if (cables[m].owner == endcap) out.push_back(m);
  }
  return out;
}

Robot parse_robot(const std::string& json_text, const std::string& source) {
  const json doc = format::parse_json<RobotError>(json_text, source);
  const Reader r(doc, source, "");
  Robot robot;
  if (const auto format = r.string("format", true); format != "tensegrity-robot/1") {
    r.fail("format", "expected \"tensegrity-robot/1\", got \"" + format + "\"");
  }
  robot.name = r.string("name");
  robot.gravity_m_per_s2 = r.non_negative("gravity_m_per_s2");
  // Ten times Jupiter's; 1e308 made ODE abort a step (fuzzing).
  if (robot.gravity_m_per_s2 > 250.0) r.fail("gravity_m_per_s2", "must be at most 250 m/s^2");
  robot.time_step_s = r.positive("time_step_s", 0.0, true);
  robot.engine =
      r.choice("engine", {"ode", "bullet"}, 0) == 0 ? Robot::PhysicsEngine::ode : Robot::PhysicsEngine::bullet;
  if (robot.time_step_s > 0.01) r.fail("time_step_s", "must be at most 0.01 s (the model is unstable above)");
  parse_nodes(r, robot);
  parse_strut(r, robot);
  const std::vector<int> strut_of = parse_struts(r, robot);
  parse_cable_defaults(r, robot);
  parse_cables(r, strut_of, robot);
  parse_ground_and_start(r, robot);
  parse_learning(r, robot);
  // The hash names the model, not its prose nor how it is learned: rewording the
  // description or changing the learning step must not orphan the policies and
  // checkpoints that record the robot they were learned on (a checkpoint records its
  // step itself, and a policy is scored at time_step_s whatever step found it).
  json hashed = doc;
  hashed.erase("description");
  hashed.erase("learning");
  robot.hash = fnv1a64_hex(hashed.dump());
  return robot;
}

Robot load_robot(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw RobotError(path.string() + ": cannot open robot description");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parse_robot(buffer.str(), path.string());
}

std::filesystem::path robot_path_named(const std::string& name) {
  const std::string file = name + ".json";
  if (const char* dir = std::getenv("TENSEGRITY_ROBOTS_DIR")) return std::filesystem::path(dir) / file;
#ifdef TENSEGRITY_SOURCE_ROBOTS_DIR
  const std::filesystem::path built_from = std::filesystem::path(TENSEGRITY_SOURCE_ROBOTS_DIR) / file;
  if (std::filesystem::exists(built_from)) return built_from;
#endif
  return std::filesystem::path("robots") / file;
}

std::filesystem::path default_robot_path() { return robot_path_named("superball-paper"); }

}  // namespace tensegrity::sim
