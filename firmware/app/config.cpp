// SPDX-License-Identifier: Apache-2.0
#include "firmware/app/config.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/limits.hpp"
#include "core/table.hpp"
#include "firmware/hal/can_bus_spec.hpp"
#include "format/json_reader.hpp"

namespace tensegrity::fw::app {
namespace {

using json = nlohmann::json;

using Reader = format::JsonReader<ConfigError>;

std::uint8_t node_id(const Reader& r, const json& v, const std::string& key) {
  if (!v.is_number_integer() || v.get<long long>() < 1 || v.get<long long>() > 127) {
    r.fail(key, "must be a CANopen node id 1..127");
  }
  return static_cast<std::uint8_t>(v.get<long long>());
}

// Whole milliseconds, 1..65535: what 0x1016 / 0x1017 can say.
void check_whole_ms(const Reader& r, const char* key, double s) {
  const double ms = s * 1e3;
  if (!(ms >= 1.0 && ms <= 65535.0) || std::fabs(ms - std::round(ms)) > 1e-6) {
    r.fail(key, "must be a whole number of milliseconds, 0.001..65.535 s (CANopen heartbeat times are in ms)");
  }
}

void parse_timeouts(const Reader& top, EndcapAppConfig& c) {
  const double period_s = static_cast<double>(c.loop_period_ns) * 1e-9;
  // Derived defaults: the producer at least one loop period (it beats from the loop).
  c.endcap_heartbeat_s = std::max(c.endcap_heartbeat_s, std::ceil(period_s * 1e3) * 1e-3);
  c.drive_consumer_heartbeat_s = 5.0 * c.endcap_heartbeat_s;
  const Reader t = top.object_or_empty("timeouts");
  t.only({"drive_heartbeat_s", "load_cell_heartbeat_s", "load_cell_sample_s", "drive_position_s", "endcap_heartbeat_s",
          "drive_consumer_heartbeat_s"});
  c.drive_heartbeat_timeout_s = t.positive("drive_heartbeat_s", c.drive_heartbeat_timeout_s);
  c.load_cell_heartbeat_timeout_s = t.positive("load_cell_heartbeat_s", c.load_cell_heartbeat_timeout_s);
  c.load_cell_sample_timeout_s = t.positive("load_cell_sample_s", c.load_cell_sample_timeout_s);
  c.drive_position_timeout_s = t.positive("drive_position_s", c.drive_position_timeout_s);
  // A freshness timeout shorter than two periods would trip on ordinary jitter.
  if (c.load_cell_sample_timeout_s < 2.0 * period_s) t.fail("load_cell_sample_s", "must be at least two loop periods");
  if (c.drive_position_timeout_s < 2.0 * period_s) t.fail("drive_position_s", "must be at least two loop periods");
  c.endcap_heartbeat_s = t.positive("endcap_heartbeat_s", c.endcap_heartbeat_s);
  check_whole_ms(t, "endcap_heartbeat_s", c.endcap_heartbeat_s);
  if (c.endcap_heartbeat_s < period_s - 1e-12) t.fail("endcap_heartbeat_s", "must be at least one loop period");
  if (!t.has("drive_consumer_heartbeat_s")) c.drive_consumer_heartbeat_s = 5.0 * c.endcap_heartbeat_s;
  c.drive_consumer_heartbeat_s = t.positive("drive_consumer_heartbeat_s", c.drive_consumer_heartbeat_s);
  check_whole_ms(t, "drive_consumer_heartbeat_s", c.drive_consumer_heartbeat_s);
  // One late heartbeat must not stop the motors (CiA 301: consumer above producer).
  if (c.drive_consumer_heartbeat_s < 2.0 * c.endcap_heartbeat_s - 1e-12) {
    t.fail("drive_consumer_heartbeat_s", "must be at least twice endcap_heartbeat_s");
  }
}

void parse_abort_connection(const Reader& top, EndcapAppConfig& c) {
  if (!top.has("drive_abort_connection")) return;
  using A = canopen::AbortConnectionOption;
  const std::string v = top.string("drive_abort_connection");
  if (v == "quick_stop") {
    c.drive_abort_connection = A::quick_stop;
  } else if (v == "disable_voltage") {
    c.drive_abort_connection = A::disable_voltage;
  } else if (v == "fault") {
    c.drive_abort_connection = A::fault_signal;
  } else {
    // "no action" is not offered: a dead end cap must stop its motors.
    top.fail("drive_abort_connection", "must be \"quick_stop\", \"disable_voltage\" or \"fault\", not \"" + v + "\"");
  }
}

// Drive, load-cell and end-cap node ids: each 1..127, none used twice.
void parse_nodes(const Reader& top, EndcapAppConfig& c) {
  const Reader nodes = top.object("nodes");
  nodes.only({"drives", "load_cell", "endcap"});
  const json& drives = nodes.at("drives");
  if (!drives.is_array() || drives.empty() || drives.size() > core::kMaxMotorsPerEndcap) {
    nodes.fail("drives",
               "must list 1.." + std::to_string(core::kMaxMotorsPerEndcap) + " drive node ids, one per motor");
  }
  c.motor_count = static_cast<std::uint32_t>(drives.size());
  std::set<int> seen;
  for (std::size_t i = 0; i < drives.size(); ++i) {
    const std::string key = "drives[" + std::to_string(i) + "]";
    c.drive_node_ids[i] = node_id(nodes, drives[i], key);
    if (!seen.insert(c.drive_node_ids[i]).second) nodes.fail(key, "node id used twice");
  }
  // c.use_load_cell is the tension guard, read before: only "tension_guard": "off"
  // runs without a load cell; a null id must not do it quietly.
  const bool no_load_cell = !nodes.has("load_cell") || nodes.at("load_cell").is_null();
  if (!c.use_load_cell) {
    if (!no_load_cell) {
      nodes.fail("load_cell",
                 "a load cell with \"tension_guard\": \"off\": drop one or the other (the guard needs the load cell)");
    }
  } else if (nodes.has("load_cell") && nodes.at("load_cell").is_null()) {
    nodes.fail("load_cell",
               "null would turn the tension guard off (no tension measured: cutoff_tension_n and "
               "hard_limit_tension_n not enforced): give the load cell's node id, or, on a bench without one, say "
               "so with \"tension_guard\": \"off\"");
  } else {
    c.load_cell_node_id = node_id(nodes, nodes.at("load_cell"), "load_cell");
    if (!seen.insert(c.load_cell_node_id).second) nodes.fail("load_cell", "node id used by a drive too");
    if (c.motor_count > 2) nodes.fail("drives", "the load cell has two channels: at most two motors");
  }
  if (nodes.has("endcap")) {
    c.endcap_node_id = node_id(nodes, nodes.at("endcap"), "endcap");
    if (!seen.insert(c.endcap_node_id).second) nodes.fail("endcap", "node id used by a drive or the load cell too");
  } else if (!seen.insert(c.endcap_node_id).second) {
    nodes.fail("endcap", "the default end-cap node id 127 is taken: give another");
  }
}

void parse_spool_and_limits(const Reader& top, EndcapAppConfig& c) {
  const Reader spool = top.object("spool");
  spool.only({"radius_m", "counts_per_rev"});
  c.spool_radius_m = spool.positive("radius_m", 0, true);
  c.counts_per_rev = spool.positive("counts_per_rev", 0, true);

  const Reader limits = top.object("limits");
  limits.only({"min_rest_length_m", "max_rest_length_m", "speed_m_per_s", "cutoff_tension_n", "hard_limit_tension_n",
               "overload"});
  core::MotorLimits& l = c.limits;
  l.min_rest_length_m = limits.positive("min_rest_length_m", 0, true);
  l.max_rest_length_m = limits.positive("max_rest_length_m", 0, true);
  l.speed_m_per_s = limits.positive("speed_m_per_s", 0, true);
  l.cutoff_tension_n = limits.positive("cutoff_tension_n", 0, true);
  l.hard_limit_tension_n = limits.positive("hard_limit_tension_n", 0, true);
  const auto& names = core::kOverloadNames;
  l.overload = static_cast<core::Overload>(limits.choice("overload", {names[0], names[1]}, 0));
  if (const core::LimitsError e = core::validate(l); e != core::LimitsError::none) {
    limits.fail(core::field_of(e), core::describe(e));
  }
}

void parse_loop(const Reader& top, EndcapAppConfig& c) {
  if (!top.has("loop")) return;
  const Reader loop = top.object("loop");
  if (loop.has("rate_hz")) loop.fail("rate_hz", "replaced by period_ns, the loop's period (1000 Hz: 1000000)");
  loop.only({"period_ns", "mode"});
  if (loop.has("period_ns")) c.loop_period_ns = loop.integer("period_ns");
  if (const std::string why = loop_period_problem(c.loop_period_ns); !why.empty()) loop.fail("period_ns", why);
  if (loop.has("mode")) {
    const std::string mode = loop.string("mode");
    if (mode == "realtime") {
      c.mode = LoopMode::realtime;
    } else if (mode == "lockstep") {
      c.mode = LoopMode::lockstep;
    } else {
      loop.fail("mode", "must be \"realtime\" or \"lockstep\", not \"" + mode + "\"");
    }
  }
}

}  // namespace

const char* to_string(LoopMode mode) { return mode == LoopMode::lockstep ? "lockstep" : "realtime"; }

std::string loop_period_problem(std::int64_t period_ns) {
  if (period_ns < core::kMinLoopPeriodNs || period_ns > core::kMaxLoopPeriodNs) {
    return "must be " + std::to_string(core::kMinLoopPeriodNs) + ".." + std::to_string(core::kMaxLoopPeriodNs) +
           " ns (the loop runs at 1 Hz to 10 kHz), not " + std::to_string(period_ns);
  }
  if (period_ns % 1'000 != 0)
    return "must be whole microseconds (the drives' 0x1006), not " + std::to_string(period_ns);
  if (!canopen::interpolation_period(period_ns)) {
    return "must be at most 255 times a power of ten ns (the drives' 0x60C2), not " + std::to_string(period_ns);
  }
  return "";
}

EndcapAppConfig parse_config(const std::string& json_text, int endcap_id, const std::string& source) {
  const json doc = format::parse_json<ConfigError>(json_text, source);
  const Reader top(doc, source, "");
  top.only({"format", "bus", "nodes", "spool", "limits", "initial_rest_length_m", "storage_dir", "loop", "timeouts",
            "drive_abort_connection", "start_on_boot", "stats_log_period_s", "dds_keystore", "tension_guard"});
  if (top.string("format") != "tensegrity-endcap/1") top.fail("format", "expected \"tensegrity-endcap/1\"");

  EndcapAppConfig c;
  if (endcap_id < 0 || endcap_id > 11)
    throw ConfigError("--id: end cap id must be 0..11, not " + std::to_string(endcap_id));
  c.endcap_id = endcap_id;

  c.bus = top.string("bus");
  CanBusSpec spec;
  std::string error;
  if (!parse_can_bus_spec(c.bus, spec, error)) top.fail("bus", error);

  // The guard stops a motor at cutoff_tension_n and the end cap at
  // hard_limit_tension_n, from the load cell's readings.
  c.use_load_cell = top.choice("tension_guard", {"on", "off"}, 0) == 0;
  parse_nodes(top, c);
  parse_spool_and_limits(top, c);
  const core::MotorLimits& l = c.limits;

  c.initial_rest_length_m = top.positive("initial_rest_length_m", 0, true);
  if (c.initial_rest_length_m < l.min_rest_length_m || c.initial_rest_length_m > l.max_rest_length_m) {
    top.fail("initial_rest_length_m", "must lie within limits.min_rest_length_m..max_rest_length_m");
  }
  c.storage_dir = top.string("storage_dir");

  parse_loop(top, c);
  parse_timeouts(top, c);
  parse_abort_connection(top, c);
  c.start_on_boot = top.boolean("start_on_boot", false);
  c.stats_log_period_s = top.positive("stats_log_period_s", c.stats_log_period_s);
  if (top.has("dds_keystore")) c.dds_keystore = top.string("dds_keystore");
  return c;
}

std::string config_to_json_text(const EndcapAppConfig& c) {
  json drives = json::array();
  for (std::uint32_t m = 0; m < c.motor_count; ++m) drives.push_back(c.drive_node_ids[m]);
  const core::MotorLimits& l = c.limits;
  const char* abort_connection =
      c.drive_abort_connection == canopen::AbortConnectionOption::disable_voltage ? "disable_voltage"
      : c.drive_abort_connection == canopen::AbortConnectionOption::fault_signal  ? "fault"
                                                                                  : "quick_stop";
  json doc = {
      {"format", "tensegrity-endcap/1"},
      {"bus", c.bus},
      {"nodes", {{"drives", drives}, {"endcap", c.endcap_node_id}}},
      {"spool", {{"radius_m", c.spool_radius_m}, {"counts_per_rev", c.counts_per_rev}}},
      {"limits",
       {{"min_rest_length_m", l.min_rest_length_m},
        {"max_rest_length_m", l.max_rest_length_m},
        {"speed_m_per_s", l.speed_m_per_s},
        {"cutoff_tension_n", l.cutoff_tension_n},
        {"hard_limit_tension_n", l.hard_limit_tension_n},
        {"overload", core::to_string(l.overload)}}},
      {"initial_rest_length_m", c.initial_rest_length_m},
      {"storage_dir", c.storage_dir.string()},
      {"loop", {{"period_ns", c.loop_period_ns}, {"mode", to_string(c.mode)}}},
      {"timeouts",
       {{"drive_heartbeat_s", c.drive_heartbeat_timeout_s},
        {"load_cell_heartbeat_s", c.load_cell_heartbeat_timeout_s},
        {"load_cell_sample_s", c.load_cell_sample_timeout_s},
        {"drive_position_s", c.drive_position_timeout_s},
        {"endcap_heartbeat_s", c.endcap_heartbeat_s},
        {"drive_consumer_heartbeat_s", c.drive_consumer_heartbeat_s}}},
      {"drive_abort_connection", abort_connection},
      {"start_on_boot", c.start_on_boot},
      {"stats_log_period_s", c.stats_log_period_s},
  };
  if (!c.dds_keystore.empty()) doc["dds_keystore"] = c.dds_keystore.string();
  if (c.use_load_cell) {
    doc["nodes"]["load_cell"] = c.load_cell_node_id;
  } else {
    doc["tension_guard"] = "off";
  }
  return doc.dump(2) + "\n";
}

EndcapAppConfig load_config(const std::filesystem::path& path, int endcap_id) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path.string() + ": cannot open the config file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_config(text.str(), endcap_id, path.string());
}

}  // namespace tensegrity::fw::app
