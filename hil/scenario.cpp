// SPDX-License-Identifier: Apache-2.0
#include "hil/scenario.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "hil/hil_error.hpp"

namespace tensegrity::hil {

namespace {

constexpr std::array<std::pair<FaultKind, const char*>, 22> kNames{{
    {FaultKind::drive_fault, "drive_fault"},
    {FaultKind::drive_silent, "drive_silent"},
    {FaultKind::load_cell_stuck, "load_cell_stuck"},
    {FaultKind::load_cell_drift, "load_cell_drift"},
    {FaultKind::drop_frames, "drop_frames"},
    {FaultKind::corrupt_frames, "corrupt_frames"},
    {FaultKind::kill_endcap, "kill_endcap"},
    {FaultKind::restart_endcap, "restart_endcap"},
    {FaultKind::cut_dds, "cut_dds"},
    {FaultKind::restore_dds, "restore_dds"},
    {FaultKind::release_spool, "release_spool"},
    {FaultKind::seize_spool, "seize_spool"},
    {FaultKind::reboot_drive, "reboot_drive"},
    {FaultKind::reboot_load_cell, "reboot_load_cell"},
    {FaultKind::drive_preoperational, "drive_preoperational"},
    {FaultKind::load_cell_stopped, "load_cell_stopped"},
    {FaultKind::hang_loop, "hang_loop"},
    {FaultKind::stop_endcap, "stop_endcap"},
    {FaultKind::mute_dds, "mute_dds"},
    {FaultKind::estop, "estop"},
    {FaultKind::clear_fault, "clear_fault"},
    {FaultKind::start, "start"},
}};

FaultKind fault_from_name(const std::string& name, const std::string& where) {
  for (const auto& [kind, text] : kNames) {
    if (name == text) return kind;
  }
  std::string known;
  for (const auto& [kind, text] : kNames) known += std::string(known.empty() ? "" : ", ") + text;
  throw HilError(where + ": unknown fault '" + name + "' (known: " + known + ")");
}

// An integer of JSON in lo..hi, read without narrowing: get<int>() of 4294967295
// is -1, which would turn a typo into "every motor".
bool integer_in(const nlohmann::json& value, std::int64_t lo, std::int64_t hi) {
  if (value.is_number_unsigned()) return value.get<std::uint64_t>() <= static_cast<std::uint64_t>(hi);
  return value.is_number_integer() && value.get<std::int64_t>() >= lo && value.get<std::int64_t>() <= hi;
}

// The parameters each fault reads (FaultInjector): one it would ignore is refused, as a
// typo in a name is, so a scenario never looks like it asks for something it does not.
std::vector<std::string> params_of(FaultKind kind) {
  switch (kind) {
    case FaultKind::drive_fault: return {"motor", "code", "release"};
    case FaultKind::drive_silent:
    case FaultKind::release_spool:
    case FaultKind::seize_spool:
    case FaultKind::reboot_drive:
    case FaultKind::drive_preoperational: return {"motor"};
    case FaultKind::load_cell_drift: return {"n_per_s"};
    case FaultKind::drop_frames: return {"probability", "duration_s"};
    case FaultKind::corrupt_frames: return {"probability", "duration_s", "kind"};
    default: return {};
  }
}

void check_param_applies(FaultKind kind, const std::string& key, const std::string& at) {
  const auto known = params_of(kind);
  if (std::find(known.begin(), known.end(), key) != known.end()) return;
  std::string list;
  for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
  throw HilError(at + ": not a parameter of " + to_string(kind) +
                 (list.empty() ? std::string(" (it takes none)") : " (its parameters: " + list + ")"));
}

void check_endcap(int endcap, int endcap_count, const std::string& where) {
  if (endcap < 0 || endcap >= endcap_count) {
    throw HilError(where + ": endcap " + std::to_string(endcap) + " out of range 0.." +
                   std::to_string(endcap_count - 1));
  }
}

FaultParams parse_params(const nlohmann::json& p, FaultKind kind, const std::string& where) {
  FaultParams out;
  if (p.is_null()) return out;
  if (!p.is_object()) throw HilError(where + ".params: must be an object");
  for (const auto& [key, value] : p.items()) {
    const std::string at = where + ".params." + key;
    if (key == "motor") {
      if (!integer_in(value, -1, 3)) throw HilError(at + ": an integer -1..3");
      out.motor = value.get<int>();
    } else if (key == "code") {
      if (!integer_in(value, 0, 0xFFFF)) throw HilError(at + ": an integer 0..65535");
      out.code = static_cast<std::uint16_t>(value.get<unsigned>());
    } else if (key == "release") {
      if (!value.is_boolean()) throw HilError(at + ": true or false");
      out.release = value.get<bool>();
    } else if (key == "n_per_s") {
      if (!value.is_number()) throw HilError(at + ": a number");
      out.n_per_s = value.get<double>();
    } else if (key == "probability") {
      if (!value.is_number() || value.get<double>() < 0.0 || value.get<double>() > 1.0)
        throw HilError(at + ": a number 0..1");
      out.probability = value.get<double>();
    } else if (key == "duration_s") {
      if (!value.is_number() || value.get<double>() < 0.0) throw HilError(at + ": a number >= 0");
      out.duration_s = value.get<double>();
    } else if (key == "kind") {
      if (value == "frame") {
        out.corrupt_kind = CorruptKind::frame;
      } else if (value == "datagram") {
        out.corrupt_kind = CorruptKind::datagram;
      } else {
        throw HilError(at + ": \"frame\" or \"datagram\"");
      }
    } else {
      throw HilError(at + ": unknown parameter");
    }
    check_param_applies(kind, key, at);
  }
  return out;
}

}  // namespace

const char* to_string(FaultKind kind) {
  for (const auto& [k, text] : kNames) {
    if (k == kind) return text;
  }
  return "unknown";
}

bool is_dds_link_fault(FaultKind kind) {
  return kind == FaultKind::cut_dds || kind == FaultKind::restore_dds || kind == FaultKind::mute_dds;
}

bool is_operator_command(FaultKind kind) {
  return kind == FaultKind::estop || kind == FaultKind::clear_fault || kind == FaultKind::start;
}

bool may_name_every_endcap(FaultKind kind) { return is_dds_link_fault(kind) || is_operator_command(kind); }

std::string ScenarioEvent::describe() const {
  std::ostringstream s;
  s << "t=" << time_s << " s " << (endcap < 0 ? std::string("all end caps") : "end cap " + std::to_string(endcap))
    << ": " << to_string(fault);
  switch (fault) {
    case FaultKind::drive_fault:
      s << " (motor " << params.motor << ", EMCY 0x" << std::hex << params.code << std::dec
        << (params.release ? ", released" : ", holding") << ")";
      break;
    case FaultKind::drive_silent:
    case FaultKind::reboot_drive:
    case FaultKind::drive_preoperational:
    case FaultKind::release_spool:
    case FaultKind::seize_spool: s << " (motor " << params.motor << ")"; break;
    case FaultKind::load_cell_drift: s << " (" << params.n_per_s << " N/s)"; break;
    case FaultKind::drop_frames:
    case FaultKind::corrupt_frames:
      s << " (p " << params.probability << ", "
        << (params.duration_s > 0 ? std::to_string(params.duration_s) + " s" : "to the end") << ")";
      break;
    default: break;
  }
  return s.str();
}

void sort_events(Scenario& scenario) {
  std::stable_sort(scenario.events.begin(), scenario.events.end(),
                   [](const ScenarioEvent& a, const ScenarioEvent& b) { return a.time_s < b.time_s; });
}

Scenario parse_scenario(const std::string& text, int endcap_count, const std::string& source) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw HilError(source + ": not JSON: " + e.what());
  }
  const nlohmann::json* list = &j;
  if (j.is_object()) {
    if (j.contains("format") && j["format"] != "tensegrity-hil-scenario/1") {
      throw HilError(source + ": format: expected \"tensegrity-hil-scenario/1\"");
    }
    if (!j.contains("events")) throw HilError(source + ": events: missing");
    list = &j["events"];
  }
  if (!list->is_array()) throw HilError(source + ": events: must be a list");
  Scenario scenario;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const auto& e = (*list)[i];
    const std::string where = source + ": events[" + std::to_string(i) + "]";
    if (!e.is_object()) throw HilError(where + ": must be an object");
    for (const auto& [key, value] : e.items()) {
      if (key != "time_s" && key != "endcap" && key != "fault" && key != "params") {
        throw HilError(where + "." + key + ": unknown field");
      }
    }
    ScenarioEvent ev;
    if (!e.contains("time_s") || !e["time_s"].is_number() || e["time_s"].get<double>() < 0.0) {
      throw HilError(where + ".time_s: a number >= 0 is required");
    }
    ev.time_s = e["time_s"].get<double>();
    if (!e.contains("fault") || !e["fault"].is_string()) throw HilError(where + ".fault: a string is required");
    ev.fault = fault_from_name(e["fault"].get<std::string>(), where + ".fault");
    const bool needs_endcap = !may_name_every_endcap(ev.fault);
    if (e.contains("endcap")) {
      const auto& endcap = e["endcap"];
      if (!endcap.is_number_integer()) throw HilError(where + ".endcap: an integer");
      if (!integer_in(endcap, 0, endcap_count - 1)) {
        throw HilError(where + ".endcap: endcap " + endcap.dump() + " out of range 0.." +
                       std::to_string(endcap_count - 1));
      }
      ev.endcap = endcap.get<int>();
    } else if (needs_endcap) {
      throw HilError(where + ".endcap: required for " + to_string(ev.fault));
    } else {
      ev.endcap = -1;  // the link of every end cap: the host's own link is cut
    }
    ev.params = parse_params(e.contains("params") ? e["params"] : nlohmann::json(), ev.fault, where);
    scenario.events.push_back(ev);
  }
  sort_events(scenario);
  return scenario;
}

void check_scenario(const Scenario& scenario, const sim::Robot& robot) {
  for (std::size_t i = 0; i < scenario.events.size(); ++i) {
    const ScenarioEvent& ev = scenario.events[i];
    const std::string where = "scenario event " + std::to_string(i) + " (" + ev.describe() + ")";
    if (ev.endcap >= robot.endcap_count() || (ev.endcap < 0 && !may_name_every_endcap(ev.fault))) {
      throw HilError(where + ": the robot has end caps 0.." + std::to_string(robot.endcap_count() - 1));
    }
    const auto params = params_of(ev.fault);
    if (ev.endcap < 0 || ev.params.motor < 0 || std::find(params.begin(), params.end(), "motor") == params.end())
      continue;
    const auto motors = robot.cables_of(ev.endcap).size();
    if (static_cast<std::size_t>(ev.params.motor) >= motors) {
      throw HilError(
          where + ": end cap " + std::to_string(ev.endcap) + " has " +
          (motors == 0 ? std::string("no motors") : "motors 0.." + std::to_string(motors - 1) + " (-1: all)"));
    }
  }
}

Scenario load_scenario(const std::filesystem::path& path, int endcap_count) {
  std::ifstream in(path);
  if (!in) throw HilError(path.string() + ": cannot read");
  std::stringstream s;
  s << in.rdbuf();
  return parse_scenario(s.str(), endcap_count, path.string());
}

ScenarioEvent disabled_cable_event(const sim::Robot& robot, int cable, CableFailure failure) {
  if (cable < 0 || cable >= robot.cable_count()) {
    throw HilError("cable " + std::to_string(cable) + ": the robot has cables 0.." +
                   std::to_string(robot.cable_count() - 1));
  }
  ScenarioEvent ev;
  ev.time_s = 0.0;
  ev.endcap = robot.cables[static_cast<std::size_t>(cable)].owner;
  ev.fault = failure == CableFailure::drive   ? FaultKind::drive_fault
             : failure == CableFailure::spool ? FaultKind::release_spool
                                              : FaultKind::seize_spool;
  const auto& mine = robot.cables_of(ev.endcap);
  for (std::size_t m = 0; m < mine.size(); ++m) {
    if (mine[m] == cable) ev.params.motor = static_cast<int>(m);
  }
  ev.params.release = true;
  return ev;
}

ScenarioEvent parse_fault_option(const std::string& text, int endcap_count) {
  const auto colon = text.find(':');
  const auto at = text.find('@');
  if (colon == std::string::npos || at == std::string::npos || at < colon) {
    throw HilError("--fault '" + text + "': expected ENDCAP:FAULT@TIME_S, e.g. 3:drive_fault@2.0");
  }
  ScenarioEvent ev;
  ev.fault = fault_from_name(text.substr(colon + 1, at - colon - 1), "--fault '" + text + "'");
  const bool all_allowed = may_name_every_endcap(ev.fault);
  const std::string who = text.substr(0, colon);
  try {
    std::size_t used = 0;
    const std::string when = text.substr(at + 1);
    ev.time_s = std::stod(when, &used);
    if (used != when.size() || !(ev.time_s >= 0.0) || !std::isfinite(ev.time_s)) throw std::invalid_argument(when);
    if (who == "all" && all_allowed) {
      ev.endcap = -1;
    } else {
      // Digits only: stoi would also take " 3", "+3" and "3000000000" (out_of_range).
      if (who.empty() || who.size() > 4 ||
          !std::all_of(who.begin(), who.end(), [](char c) { return c >= '0' && c <= '9'; }))
        throw std::invalid_argument(who);
      ev.endcap = std::stoi(who);
    }
  } catch (const std::exception&) {
    throw HilError("--fault '" + text + "': ENDCAP must be a number" + std::string(all_allowed ? " or 'all'" : "") +
                   " and TIME_S a number >= 0");
  }
  if (ev.endcap >= 0) check_endcap(ev.endcap, endcap_count, "--fault '" + text + "'");
  return ev;
}

}  // namespace tensegrity::hil
