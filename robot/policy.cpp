// SPDX-License-Identifier: Apache-2.0
#include "robot/policy.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <system_error>

#include "format/atomic_file.hpp"
#include "format/policy_format.hpp"

namespace tensegrity::sim {
namespace {

using nlohmann::json;

[[noreturn]] void fail(const std::string& source, const std::string& field, const std::string& message) {
  throw PolicyError(source + ": " + field + ": " + message);
}

double finite_number(const json& v, const std::string& source, const std::string& field) {
  if (!v.is_number()) fail(source, field, "must be a number");
  const double x = v.get<double>();
  if (!std::isfinite(x)) fail(source, field, "must be finite");
  return x;
}

long long integer(const json& v, const std::string& source, const std::string& field) {
  if (!v.is_number_integer()) fail(source, field, "must be an integer");
  return v.get<long long>();
}

// provenance.gait: what the scoring episode saw of the struts' spin and the ground.
void read_gait(const json& provenance, const Robot& robot, const std::string& source, Provenance& pr) {
  const auto g = provenance.find("gait");
  if (g == provenance.end()) return;
  if (!g->is_object()) fail(source, "provenance.gait", "must be an object");
  pr.axial_spin_rms_rad_per_s =
      finite_number(g->value("axial_spin_rms_rad_per_s", json()), source, "provenance.gait.axial_spin_rms_rad_per_s");
  pr.axial_spin_max_rad_per_s =
      finite_number(g->value("axial_spin_max_rad_per_s", json()), source, "provenance.gait.axial_spin_max_rad_per_s");
  const long long touched =
      integer(g->value("endcaps_touched_ground", json()), source, "provenance.gait.endcaps_touched_ground");
  if (touched < 0 || touched > robot.node_count()) {
    fail(source, "provenance.gait.endcaps_touched_ground", "must be within 0.." + std::to_string(robot.node_count()));
  }
  pr.endcaps_touched_ground = static_cast<int>(touched);
  if (g->contains("min_strut_gap_m")) {
    pr.min_strut_gap_m = finite_number(g->at("min_strut_gap_m"), source, "provenance.gait.min_strut_gap_m");
  }
  if (g->contains("strut_overlap_s")) {
    const double s = finite_number(g->at("strut_overlap_s"), source, "provenance.gait.strut_overlap_s");
    if (s < 0.0) fail(source, "provenance.gait.strut_overlap_s", "must be >= 0");
    pr.strut_overlap_s = s;
  }
  if (g->contains("heading_deg")) {
    const double h = finite_number(g->at("heading_deg"), source, "provenance.gait.heading_deg");
    if (h <= -180.0 || h > 180.0) fail(source, "provenance.gait.heading_deg", "must be within (-180, 180] degrees");
    pr.heading_deg = h;
  }
}

}  // namespace

namespace {

// provenance.population / replace / teams: all three or none (older policy files
// have none), each a size the coevolution could have run with.
void read_sizes(const json& p, const std::string& source, Provenance& pr) {
  const int given = static_cast<int>(p.contains("population")) + static_cast<int>(p.contains("replace")) +
                    static_cast<int>(p.contains("teams"));
  if (given == 0) return;
  if (given != 3) fail(source, "provenance.population", "population, replace and teams go together");
  const long long population = integer(p["population"], source, "provenance.population");
  const long long replace = integer(p["replace"], source, "provenance.replace");
  const long long teams = integer(p["teams"], source, "provenance.teams");
  if (population < 2 || population > 100000) fail(source, "provenance.population", "must be within 2..100000");
  if (replace < 1 || replace > population / 2) fail(source, "provenance.replace", "must be within 1..population/2");
  if (teams < 1 || teams > 1000000) fail(source, "provenance.teams", "must be within 1..1000000");
  pr.population = static_cast<int>(population);
  pr.replace = static_cast<int>(replace);
  pr.teams = static_cast<int>(teams);
}

// The provenance's fields beside the gait (read_gait), checked where present.
void read_provenance(const json& p, const std::string& source, Provenance& pr) {
  pr.method = p.value("method", "");
  if (p.contains("seed")) pr.seed = static_cast<std::uint64_t>(integer(p["seed"], source, "provenance.seed"));
  if (p.contains("episodes")) pr.episodes = integer(p["episodes"], source, "provenance.episodes");
  if (p.contains("score_m")) pr.score_m = finite_number(p["score_m"], source, "provenance.score_m");
  pr.robot_hash = p.value("robot_hash", "");
  pr.created_by = p.value("created_by", "");
  if (p.contains("symmetry")) {
    if (!p["symmetry"].is_string() || p["symmetry"].get<std::string>().empty()) {
      fail(source, "provenance.symmetry", "must be a non-empty string");
    }
    pr.symmetry = p["symmetry"].get<std::string>();
  }
  read_sizes(p, source, pr);
  const auto m = p.find("mutation");
  if (m == p.end()) return;
  if (!m->is_object()) fail(source, "provenance.mutation", "must be an object");
  // Policies from before the author's operator existed were bred by the Gaussian one.
  const json op = m->value("operator", json("gaussian"));
  if (!op.is_string() || (op != "gaussian" && op != "author")) {
    fail(source, "provenance.mutation.operator", "must be \"gaussian\" or \"author\"");
  }
  pr.mutation = op.get<std::string>();
  pr.sigma_m = finite_number(m->value("sigma_m", json()), source, "provenance.mutation.sigma_m");
  pr.sigma_final_m = finite_number(m->value("sigma_final_m", json()), source, "provenance.mutation.sigma_final_m");
  pr.anneal_episodes = integer(m->value("anneal_episodes", json()), source, "provenance.mutation.anneal_episodes");
  pr.anneal_start_episodes =
      integer(m->value("anneal_start_episodes", json(0)), source, "provenance.mutation.anneal_start_episodes");
  if (pr.sigma_m < 0.0 || pr.sigma_final_m < 0.0 || pr.anneal_episodes < 0 || pr.anneal_start_episodes < 0) {
    fail(source, "provenance.mutation", "steps and anneal_episodes must be >= 0");
  }
}

// What the file must be for this robot: its name, one entry per cable, each owned
// as the robot says, every rest length within the robot's limits.
void check_against_robot(const format::PolicyDocument& doc, const Robot& robot, const std::string& source) {
  if (doc.robot.empty()) fail(source, "robot", "missing");
  if (doc.robot != robot.name) {
    fail(source, "robot", "policy is for robot \"" + doc.robot + "\", not \"" + robot.name + "\"");
  }
  if (static_cast<int>(doc.cables.size()) != robot.cable_count()) {
    fail(source, "cables",
         "has " + std::to_string(doc.cables.size()) + " entries, the robot has " + std::to_string(robot.cable_count()) +
             " cables");
  }
  for (std::size_t i = 0; i < doc.cables.size(); ++i) {
    const std::string path = "cables[" + std::to_string(i) + "]";
    const format::PolicyCable& c = doc.cables[i];
    if (c.cable >= robot.cable_count()) fail(source, path + ".cable", "no such cable");
    if (c.owner != robot.cables[c.cable].owner) {
      fail(source, path + ".owner",
           "cable " + std::to_string(c.cable) + " is owned by end cap " + std::to_string(robot.cables[c.cable].owner) +
               ", not " + std::to_string(c.owner));
    }
    format::check_rest_lengths(doc, i, robot.motor, source);
  }
}

}  // namespace

Policy parse_policy(const std::string& json_text, const Robot& robot, const std::string& source) {
  try {
    const format::PolicyDocument doc = format::parse_policy_document(json_text, source);
    check_against_robot(doc, robot, source);
    Policy policy;
    policy.robot = doc.robot;
    policy.period_s = doc.period_s;
    policy.complexity = doc.complexity;
    policy.cables.resize(doc.cables.size());
    for (const format::PolicyCable& c : doc.cables) policy.cables[c.cable] = {c.cable, c.owner, c.rest_lengths_m};
    if (doc.provenance.is_object()) {
      read_provenance(doc.provenance, source, policy.provenance);
      read_gait(doc.provenance, robot, source, policy.provenance);
    }
    return policy;
  } catch (const format::PolicyFormatError& e) {
    throw PolicyError(e.what());
  }
}

Policy load_policy(const std::filesystem::path& path, const Robot& robot) {
  std::ifstream in(path);
  if (!in) throw PolicyError(path.string() + ": cannot open policy file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parse_policy(buffer.str(), robot, path.string());
}

std::filesystem::path robot_path_for_policy(const std::filesystem::path& policy_path) {
  std::ifstream in(policy_path);
  const json doc = json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (doc.is_object()) {
    const auto it = doc.find("robot");
    // A name, not a path: nothing outside the robots directory is reachable from a file.
    if (it != doc.end() && it->is_string()) {
      const std::string name = it->get<std::string>();
      if (!name.empty() && name.find_first_of("/\\") == std::string::npos && name.front() != '.') {
        const std::filesystem::path path = robot_path_named(name);
        if (std::filesystem::exists(path)) return path;
      }
    }
  }
  return default_robot_path();
}

std::string policy_to_json(const Policy& policy) {
  json cables = json::array();
  for (const auto& c : policy.cables) {
    cables.push_back({{"cable", c.cable}, {"owner", c.owner}, {"rest_lengths_m", c.rest_lengths_m}});
  }
  json doc = {
      {"format", "tensegrity-policy/1"},
      {"robot", policy.robot},
      {"period_s", policy.period_s},
      {"complexity", policy.complexity},
      {"cables", cables},
      {"provenance",
       {{"method", policy.provenance.method},
        {"seed", policy.provenance.seed},
        {"episodes", policy.provenance.episodes},
        {"score_m", policy.provenance.score_m},
        {"robot_hash", policy.provenance.robot_hash},
        {"created_by", policy.provenance.created_by}}},
  };
  const Provenance& pr = policy.provenance;
  if (pr.population > 0) {
    doc["provenance"]["population"] = pr.population;
    doc["provenance"]["replace"] = pr.replace;
    doc["provenance"]["teams"] = pr.teams;
  }
  if (pr.sigma_m > 0.0) {
    doc["provenance"]["mutation"] = {{"operator", pr.mutation},
                                     {"sigma_m", pr.sigma_m},
                                     {"sigma_final_m", pr.sigma_final_m},
                                     {"anneal_start_episodes", pr.anneal_start_episodes},
                                     {"anneal_episodes", pr.anneal_episodes}};
  }
  if (pr.endcaps_touched_ground >= 0) {
    doc["provenance"]["gait"] = {{"axial_spin_rms_rad_per_s", pr.axial_spin_rms_rad_per_s},
                                 {"axial_spin_max_rad_per_s", pr.axial_spin_max_rad_per_s},
                                 {"endcaps_touched_ground", pr.endcaps_touched_ground}};
    if (pr.min_strut_gap_m) doc["provenance"]["gait"]["min_strut_gap_m"] = *pr.min_strut_gap_m;
    if (pr.strut_overlap_s) doc["provenance"]["gait"]["strut_overlap_s"] = *pr.strut_overlap_s;
    if (pr.heading_deg) doc["provenance"]["gait"]["heading_deg"] = *pr.heading_deg;
  }
  if (!pr.symmetry.empty()) doc["provenance"]["symmetry"] = pr.symmetry;
  return doc.dump(2) + "\n";
}

void save_policy(const std::filesystem::path& path, const Policy& policy) {
  try {
    format::write_file_atomic(path, policy_to_json(policy));
  } catch (const std::system_error& e) {
    throw PolicyError(path.string() + ": cannot save: " + e.what());
  }
}

core::EndcapTable endcap_table(const Policy& policy, const Robot& robot, int endcap) {
  // The end cap's own rule (format::endcap_table_of), so that the simulator, the HIL
  // and the upload give an end cap the table it would take from the file itself.
  format::PolicyDocument doc;
  doc.robot = policy.robot;
  doc.period_s = policy.period_s;
  doc.complexity = policy.complexity;
  doc.cables.reserve(policy.cables.size());
  for (const CablePolicy& c : policy.cables) doc.cables.push_back({c.cable, c.owner, c.rest_lengths_m});
  const auto motor_count = static_cast<std::uint32_t>(robot.cables_of(endcap).size());
  try {
    return format::endcap_table_of(doc, endcap, motor_count, robot.motor, "policy");
  } catch (const format::PolicyFormatError& e) {
    throw PolicyError(e.what());
  }
}

}  // namespace tensegrity::sim
