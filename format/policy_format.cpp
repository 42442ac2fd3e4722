// SPDX-License-Identifier: Apache-2.0
#include "format/policy_format.hpp"

#include <map>
#include <set>
#include <sstream>

#include "format/json_reader.hpp"

namespace tensegrity::format {
namespace {

using json = nlohmann::json;
using Reader = JsonReader<PolicyFormatError>;

PolicyCable parse_cable(const Reader& entry, int complexity) {
  PolicyCable cable;
  const std::int64_t index = entry.integer("cable");
  if (index < 0 || index > 1'000'000) entry.fail("cable", "no such cable");
  cable.cable = static_cast<int>(index);
  const std::int64_t owner = entry.integer("owner");
  if (owner < 0 || owner > 1'000'000) entry.fail("owner", "no such end cap");
  cable.owner = static_cast<int>(owner);
  const json& values = entry.at("rest_lengths_m");
  if (!values.is_array() || values.size() != static_cast<std::size_t>(complexity)) {
    entry.fail("rest_lengths_m", "must hold exactly " + std::to_string(complexity) + " values");
  }
  for (std::size_t j = 0; j < values.size(); ++j) {
    cable.rest_lengths_m.push_back(
        entry.number_at(values[j], entry.field("rest_lengths_m") + "[" + std::to_string(j) + "]"));
  }
  return cable;
}

}  // namespace

PolicyDocument parse_policy_document(const std::string& json_text, const std::string& source) {
  const json doc = parse_json<PolicyFormatError>(json_text, source);
  const Reader r(doc, source, "");
  if (!r.has("format") || !r.at("format").is_string() || r.at("format").get<std::string>() != kPolicyFormat) {
    r.fail("format", std::string("expected \"") + kPolicyFormat + "\"");
  }
  PolicyDocument out;
  if (r.has("robot")) out.robot = r.string("robot");
  out.period_s = r.number("period_s");
  if (!(out.period_s > 0.0) || out.period_s > core::kMaxPeriodS) r.fail("period_s", "must be within (0, 3600] s");
  const std::int64_t complexity = r.integer("complexity");
  if (complexity < 1 || complexity > static_cast<std::int64_t>(core::kMaxComplexity)) {
    r.fail("complexity", "must be 1.." + std::to_string(core::kMaxComplexity));
  }
  out.complexity = static_cast<int>(complexity);
  const json& cables = r.array("cables");
  std::set<int> seen;
  for (std::size_t i = 0; i < cables.size(); ++i) {
    const Reader entry = r.element("cables", i);
    PolicyCable cable = parse_cable(entry, out.complexity);
    if (!seen.insert(cable.cable).second) {
      entry.fail("cable", "cable " + std::to_string(cable.cable) + " appears twice");
    }
    out.cables.push_back(std::move(cable));
  }
  if (r.has("provenance")) {
    if (!r.at("provenance").is_object()) r.fail("provenance", "must be an object");
    out.provenance = r.at("provenance");
  }
  return out;
}

void check_rest_lengths(const PolicyDocument& doc, std::size_t entry, const core::MotorLimits& limits,
                        const std::string& source) {
  const auto& values = doc.cables.at(entry).rest_lengths_m;
  for (std::size_t j = 0; j < values.size(); ++j) {
    const double v = values[j];
    if (v >= limits.min_rest_length_m && v <= limits.max_rest_length_m) continue;
    std::ostringstream msg;
    msg << source << ": cables[" << entry << "].rest_lengths_m[" << j << "]: " << v
        << " m is outside the rest-length limits [" << limits.min_rest_length_m << ", " << limits.max_rest_length_m
        << "] m";
    throw PolicyFormatError(msg.str());
  }
}

core::EndcapTable endcap_table_of(const PolicyDocument& doc, int endcap_id, std::uint32_t motor_count,
                                  const core::MotorLimits& limits, const std::string& source) {
  if (motor_count > core::kMaxMotorsPerEndcap) {
    throw PolicyFormatError(source + ": end cap " + std::to_string(endcap_id) + " has " + std::to_string(motor_count) +
                            " motors, more than the core's " + std::to_string(core::kMaxMotorsPerEndcap));
  }
  std::map<int, std::size_t> owned;  // cable index -> entry, ordered by cable index
  for (std::size_t i = 0; i < doc.cables.size(); ++i) {
    if (doc.cables[i].owner == endcap_id) owned.emplace(doc.cables[i].cable, i);
  }
  if (owned.size() != motor_count) {
    throw PolicyFormatError(source + ": cables: end cap " + std::to_string(endcap_id) + " owns " +
                            std::to_string(owned.size()) + " cables in this policy, but has " +
                            std::to_string(motor_count) + " motors");
  }
  core::EndcapTable table;
  table.motor_count = motor_count;
  table.complexity = static_cast<std::uint32_t>(doc.complexity);
  table.period_s = doc.period_s;
  std::uint32_t m = 0;
  for (const auto& [cable, i] : owned) {
    check_rest_lengths(doc, i, limits, source);
    const auto& values = doc.cables[i].rest_lengths_m;
    for (std::size_t j = 0; j < values.size(); ++j) table.rest_length_m[m][j] = values[j];
    ++m;
  }
  if (const core::TableError e = core::validate(table, motor_count, limits); e != core::TableError::none) {
    throw PolicyFormatError(source + ": (end cap " + std::to_string(endcap_id) + " table): " + core::describe(e));
  }
  return table;
}

}  // namespace tensegrity::format
