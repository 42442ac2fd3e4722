// SPDX-License-Identifier: Apache-2.0
#include "firmware/app/policy_file.hpp"

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

namespace tensegrity::fw::app {
namespace {
using json = nlohmann::json;

[[noreturn]] void fail(const std::string& source, const std::string& field, const std::string& what) {
  throw PolicyFileError(source + ": " + field + ": " + what);
}
const json& need(const json& j, const char* key, const std::string& source, const std::string& path) {
  const std::string field = path.empty() ? key : path + "." + key;
  if (!j.is_object() || !j.contains(key)) fail(source, field, "missing");
  return j.at(key);
}
long long integer(const json& v, const std::string& source, const std::string& field) {
  if (!v.is_number_integer()) fail(source, field, "must be an integer");
  return v.get<long long>();
}
}  // namespace

core::EndcapTable endcap_table_from_policy(const std::string& json_text, int endcap_id, std::uint32_t motor_count,
                                           const core::MotorLimits& limits, const std::string& source) {
  json doc;
  try {
    doc = json::parse(json_text);
  } catch (const json::exception& e) {
    throw PolicyFileError(source + ": not valid JSON: " + e.what());
  }
  if (!doc.is_object()) fail(source, "(top level)", "must be an object");
  const json& format = need(doc, "format", source, "");
  if (!format.is_string() || format.get<std::string>() != "tensegrity-policy/1") {
    fail(source, "format", "expected \"tensegrity-policy/1\"");
  }
  core::EndcapTable table;
  const json& period = need(doc, "period_s", source, "");
  if (!period.is_number() || !std::isfinite(period.get<double>())) fail(source, "period_s", "must be a finite number");
  table.period_s = period.get<double>();
  const long long complexity = integer(need(doc, "complexity", source, ""), source, "complexity");
  if (complexity < 1 || complexity > static_cast<long long>(core::kMaxComplexity)) {
    fail(source, "complexity", "must be 1.." + std::to_string(core::kMaxComplexity));
  }
  table.complexity = static_cast<std::uint32_t>(complexity);

  const json& cables = need(doc, "cables", source, "");
  if (!cables.is_array()) fail(source, "cables", "must be an array");
  std::map<long long, std::size_t> owned;  // cable index -> entry, ordered by cable index
  for (std::size_t i = 0; i < cables.size(); ++i) {
    const std::string path = "cables[" + std::to_string(i) + "]";
    const long long owner = integer(need(cables[i], "owner", source, path), source, path + ".owner");
    if (owner != endcap_id) continue;
    const long long cable = integer(need(cables[i], "cable", source, path), source, path + ".cable");
    if (!owned.emplace(cable, i).second) fail(source, path + ".cable", "cable listed twice");
  }
  if (owned.size() != motor_count) {
    fail(source, "cables",
         "end cap " + std::to_string(endcap_id) + " owns " + std::to_string(owned.size()) +
             " cables in this policy, but has " + std::to_string(motor_count) + " motors");
  }
  table.motor_count = motor_count;
  std::uint32_t m = 0;
  for (const auto& [cable, i] : owned) {
    const std::string path = "cables[" + std::to_string(i) + "].rest_lengths_m";
    const json& values = need(cables[i], "rest_lengths_m", source, "cables[" + std::to_string(i) + "]");
    if (!values.is_array() || values.size() != table.complexity) {
      fail(source, path, "must hold exactly " + std::to_string(table.complexity) + " values");
    }
    for (std::uint32_t j = 0; j < table.complexity; ++j) {
      const json& v = values[j];
      const std::string field = path + "[" + std::to_string(j) + "]";
      if (!v.is_number() || !std::isfinite(v.get<double>())) fail(source, field, "must be a finite number");
      const double x = v.get<double>();
      if (x < limits.min_rest_length_m || x > limits.max_rest_length_m) {
        std::ostringstream msg;
        msg << x << " m is outside this end cap's rest-length limits [" << limits.min_rest_length_m << ", "
            << limits.max_rest_length_m << "] m";
        fail(source, field, msg.str());
      }
      table.rest_length_m[m][j] = x;
    }
    ++m;
  }
  if (const core::TableError e = core::validate(table, motor_count, limits); e != core::TableError::none) {
    fail(source, "(end cap " + std::to_string(endcap_id) + " table)", core::describe(e));
  }
  return table;
}

core::EndcapTable load_endcap_table(const std::filesystem::path& path, int endcap_id, std::uint32_t motor_count,
                                    const core::MotorLimits& limits) {
  std::ifstream in(path);
  if (!in) throw PolicyFileError(path.string() + ": cannot open the policy file");
  std::ostringstream text;
  text << in.rdbuf();
  return endcap_table_from_policy(text.str(), endcap_id, motor_count, limits, path.string());
}

}  // namespace tensegrity::fw::app
