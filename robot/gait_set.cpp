// SPDX-License-Identifier: Apache-2.0
#include "robot/gait_set.hpp"

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <system_error>

#include "format/atomic_file.hpp"
#include "format/json_reader.hpp"
#include "robot/start_frame.hpp"

namespace tensegrity::sim {
namespace {

using nlohmann::json;
using Reader = format::JsonReader<GaitSetError>;

std::array<int, 3> read_face(const Reader& r, const std::vector<HullFace>& faces, int nodes) {
  const json& v = r.array("face");
  if (v.size() != 3) r.fail("face", "must hold the 3 end caps of a face");
  std::array<int, 3> face{};
  for (std::size_t k = 0; k < 3; ++k) {
    const std::string path = r.field("face") + "[" + std::to_string(k) + "]";
    if (!v[k].is_number_integer()) r.fail_at(path, "must be an integer");
    const auto e = v[k].get<long long>();
    if (e < 0 || e >= nodes) r.fail_at(path, "no such end cap (the robot has " + std::to_string(nodes) + ")");
    face[k] = static_cast<int>(e);
  }
  std::sort(face.begin(), face.end());
  const bool on_hull = std::any_of(faces.begin(), faces.end(), [&](const HullFace& f) { return f.nodes == face; });
  if (!on_hull) {
    r.fail("face", "end caps " + std::to_string(face[0]) + ", " + std::to_string(face[1]) + ", " +
                       std::to_string(face[2]) + " are not a face the robot can stand on (a face of its hull)");
  }
  return face;
}

Gait read_gait(const Reader& r, const Robot& robot, const std::vector<HullFace>& faces, const std::string& source) {
  r.only({"name", "symmetry", "face", "heading_deg", "speed_m_per_min", "basis", "policy"});
  Gait g;
  g.name = r.string("name");
  if (r.has("symmetry")) g.symmetry = r.string("symmetry");
  g.face = read_face(r, faces, robot.node_count());
  g.heading_deg = r.number("heading_deg");
  if (g.heading_deg <= -180.0 || g.heading_deg > 180.0) r.fail("heading_deg", "must be within (-180, 180] degrees");
  g.speed_m_per_min = r.non_negative("speed_m_per_min", 0.0, true);
  if (!r.has("basis")) r.fail("basis", "missing");
  g.basis = r.choice("basis", {"measured", "symmetry"}, 0) == 0 ? "measured" : "symmetry";
  const json& policy = r.at("policy");
  if (!policy.is_object()) r.fail("policy", "must be a policy object (tensegrity-policy/1)");
  try {
    g.policy = parse_policy(policy.dump(), robot, source + ": " + r.field("policy"));
  } catch (const PolicyError& e) {
    throw GaitSetError(e.what());
  }
  return g;
}

}  // namespace

GaitSet parse_gait_set(const std::string& json_text, const Robot& robot, const std::string& source) {
  const json doc = format::parse_json<GaitSetError>(json_text, source);
  const Reader r(doc, source, "");
  r.only({"format", "robot", "robot_hash", "source", "duration_s", "gaits"});
  if (!r.has("format") || !r.at("format").is_string() || r.at("format").get<std::string>() != kGaitSetFormat) {
    r.fail("format", std::string("expected \"") + kGaitSetFormat + "\"");
  }
  GaitSet set;
  set.robot = r.string("robot");
  if (set.robot != robot.name)
    r.fail("robot", "the set is for robot \"" + set.robot + "\", not \"" + robot.name + "\"");
  if (r.has("robot_hash")) set.robot_hash = r.string("robot_hash");
  if (r.has("source")) set.source = r.string("source");
  set.duration_s = r.positive("duration_s", 0.0, true);
  const json& gaits = r.array("gaits");
  if (gaits.empty()) r.fail("gaits", "must hold at least one gait");
  const std::vector<HullFace> faces = hull_faces(robot);
  std::set<std::string> names;
  for (std::size_t i = 0; i < gaits.size(); ++i) {
    const Reader entry = r.element("gaits", i);
    Gait g = read_gait(entry, robot, faces, source);
    if (!names.insert(g.name).second) entry.fail("name", "\"" + g.name + "\" appears twice");
    set.gaits.push_back(std::move(g));
  }
  return set;
}

GaitSet load_gait_set(const std::filesystem::path& path, const Robot& robot) {
  std::ifstream in(path);
  if (!in) throw GaitSetError(path.string() + ": cannot open gait set file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parse_gait_set(buffer.str(), robot, path.string());
}

std::string gait_set_to_json(const GaitSet& set) {
  json gaits = json::array();
  for (const Gait& g : set.gaits) {
    json entry = {{"name", g.name}};
    if (!g.symmetry.empty()) entry["symmetry"] = g.symmetry;
    entry["face"] = g.face;
    entry["heading_deg"] = g.heading_deg;
    entry["speed_m_per_min"] = g.speed_m_per_min;
    entry["basis"] = g.basis;
    entry["policy"] = json::parse(policy_to_json(g.policy));
    gaits.push_back(std::move(entry));
  }
  json doc = {{"format", kGaitSetFormat}, {"robot", set.robot}};
  if (!set.robot_hash.empty()) doc["robot_hash"] = set.robot_hash;
  if (!set.source.empty()) doc["source"] = set.source;
  doc["duration_s"] = set.duration_s;
  doc["gaits"] = std::move(gaits);
  return doc.dump(2) + "\n";
}

void save_gait_set(const std::filesystem::path& path, const GaitSet& set) {
  try {
    format::write_file_atomic(path, gait_set_to_json(set));
  } catch (const std::system_error& e) {
    throw GaitSetError(path.string() + ": cannot save: " + e.what());
  }
}

}  // namespace tensegrity::sim
