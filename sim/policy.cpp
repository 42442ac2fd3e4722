// SPDX-License-Identifier: Apache-2.0
#include "sim/policy.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <system_error>

#include "format/atomic_file.hpp"

namespace tensegrity::sim {
namespace {

using nlohmann::json;

[[noreturn]] void fail(const std::string& source, const std::string& field, const std::string& message) {
  throw PolicyError(source + ": " + field + ": " + message);
}

const json& need(const json& j, const std::string& key, const std::string& source, const std::string& path) {
  if (!j.is_object()) fail(source, path.empty() ? "(top)" : path, "must be an object");
  const auto it = j.find(key);
  if (it == j.end()) fail(source, path.empty() ? key : path + "." + key, "missing");
  return *it;
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
}

}  // namespace

Policy parse_policy(const std::string& json_text, const Robot& robot, const std::string& source) {
  json doc;
  try {
    doc = json::parse(json_text);
  } catch (const json::exception& e) {
    throw PolicyError(source + ": not valid JSON: " + e.what());
  }
  Policy policy;
  const json& format = need(doc, "format", source, "");
  if (!format.is_string() || format.get<std::string>() != "tensegrity-policy/1") {
    fail(source, "format", "expected \"tensegrity-policy/1\"");
  }
  const json& name = need(doc, "robot", source, "");
  if (!name.is_string()) fail(source, "robot", "must be a string");
  policy.robot = name.get<std::string>();
  if (policy.robot != robot.name) {
    fail(source, "robot", "policy is for robot \"" + policy.robot + "\", not \"" + robot.name + "\"");
  }
  policy.period_s = finite_number(need(doc, "period_s", source, ""), source, "period_s");
  if (!(policy.period_s > 0.0) || policy.period_s > 3600.0) fail(source, "period_s", "must be within (0, 3600] s");
  const long long complexity = integer(need(doc, "complexity", source, ""), source, "complexity");
  if (complexity < 1 || complexity > static_cast<long long>(core::kMaxComplexity)) {
    fail(source, "complexity", "must be 1.." + std::to_string(core::kMaxComplexity));
  }
  policy.complexity = static_cast<int>(complexity);

  const json& cables = need(doc, "cables", source, "");
  if (!cables.is_array()) fail(source, "cables", "must be an array");
  if (static_cast<int>(cables.size()) != robot.cable_count()) {
    fail(source, "cables",
         "has " + std::to_string(cables.size()) + " entries, the robot has " + std::to_string(robot.cable_count()) +
             " cables");
  }
  policy.cables.resize(cables.size());
  std::vector<bool> seen(cables.size(), false);
  for (std::size_t i = 0; i < cables.size(); ++i) {
    const std::string path = "cables[" + std::to_string(i) + "]";
    const json& entry = cables[i];
    const long long index = integer(need(entry, "cable", source, path), source, path + ".cable");
    if (index < 0 || index >= robot.cable_count()) fail(source, path + ".cable", "no such cable");
    if (seen[index]) fail(source, path + ".cable", "cable " + std::to_string(index) + " appears twice");
    seen[index] = true;
    CablePolicy& cable = policy.cables[index];
    cable.cable = static_cast<int>(index);
    const long long owner = integer(need(entry, "owner", source, path), source, path + ".owner");
    if (owner != robot.cables[index].owner) {
      fail(source, path + ".owner",
           "cable " + std::to_string(index) + " is owned by end cap " + std::to_string(robot.cables[index].owner) +
               ", not " + std::to_string(owner));
    }
    cable.owner = static_cast<int>(owner);
    const json& values = need(entry, "rest_lengths_m", source, path);
    if (!values.is_array() || static_cast<long long>(values.size()) != complexity) {
      fail(source, path + ".rest_lengths_m", "must hold exactly " + std::to_string(complexity) + " values");
    }
    for (std::size_t j = 0; j < values.size(); ++j) {
      const std::string field = path + ".rest_lengths_m[" + std::to_string(j) + "]";
      const double v = finite_number(values[j], source, field);
      if (v < robot.motor.min_rest_length_m || v > robot.motor.max_rest_length_m) {
        std::ostringstream msg;
        msg << v << " m is outside the rest-length limits [" << robot.motor.min_rest_length_m << ", "
            << robot.motor.max_rest_length_m << "] m";
        fail(source, field, msg.str());
      }
      cable.rest_lengths_m.push_back(v);
    }
  }

  if (const auto it = doc.find("provenance"); it != doc.end()) {
    const json& p = *it;
    if (!p.is_object()) fail(source, "provenance", "must be an object");
    policy.provenance.method = p.value("method", "");
    if (p.contains("seed"))
      policy.provenance.seed = static_cast<std::uint64_t>(integer(p["seed"], source, "provenance.seed"));
    if (p.contains("episodes")) policy.provenance.episodes = integer(p["episodes"], source, "provenance.episodes");
    if (p.contains("score_m")) policy.provenance.score_m = finite_number(p["score_m"], source, "provenance.score_m");
    policy.provenance.robot_hash = p.value("robot_hash", "");
    policy.provenance.created_by = p.value("created_by", "");
    if (const auto m = p.find("mutation"); m != p.end()) {
      if (!m->is_object()) fail(source, "provenance.mutation", "must be an object");
      Provenance& pr = policy.provenance;
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
  }
  if (const auto it = doc.find("provenance"); it != doc.end()) read_gait(*it, robot, source, policy.provenance);
  return policy;
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
  }
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
  core::EndcapTable table;
  const std::vector<int> owned = robot.cables_of(endcap);
  if (owned.size() > core::kMaxMotorsPerEndcap) {
    throw PolicyError("end cap " + std::to_string(endcap) + " owns more cables than the core supports");
  }
  table.motor_count = static_cast<std::uint32_t>(owned.size());
  table.complexity = static_cast<std::uint32_t>(policy.complexity);
  table.period_s = policy.period_s;
  for (std::size_t k = 0; k < owned.size(); ++k) {
    const auto& values = policy.cables.at(owned[k]).rest_lengths_m;
    for (std::size_t j = 0; j < values.size(); ++j) table.rest_length_m[k][j] = values[j];
  }
  return table;
}

}  // namespace tensegrity::sim
