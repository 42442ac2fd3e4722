// SPDX-License-Identifier: Apache-2.0
#include "firmware/app/config.hpp"

#include <cmath>
#include <fstream>
#include <initializer_list>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "firmware/core/table.hpp"
#include "firmware/hal/can_bus_spec.hpp"

namespace tensegrity::fw::app {
namespace {

using json = nlohmann::json;

// Reads one JSON object, remembering the source and the path for error text.
class Reader {
 public:
  Reader(const json& j, std::string source, std::string path) : j_(j), source_(std::move(source)), path_(std::move(path)) {
    if (!j_.is_object()) fail("", "must be an object");
  }

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw ConfigError(source_ + ": " + field(key) + ": " + what);
  }
  std::string field(const std::string& key) const {
    if (path_.empty()) return key.empty() ? "(top level)" : key;
    return key.empty() ? path_ : path_ + "." + key;
  }
  void only(std::initializer_list<const char*> keys) const {
    for (const auto& [k, v] : j_.items()) {
      bool known = false;
      for (const char* allowed : keys) known = known || k == allowed;
      if (!known) fail(k, "unknown field");
    }
  }
  bool has(const char* key) const { return j_.contains(key); }
  const json& at(const char* key) const {
    if (!j_.contains(key)) fail(key, "missing");
    return j_.at(key);
  }
  Reader object(const char* key) const { return Reader(at(key), source_, field(key)); }

  double number(const char* key, double fallback, bool required = false) const {
    if (!has(key)) {
      if (required) fail(key, "missing");
      return fallback;
    }
    const json& v = j_.at(key);
    if (!v.is_number()) fail(key, "must be a number");
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(key, "must be finite");
    return x;
  }
  double positive(const char* key, double fallback, bool required = false) const {
    const double x = number(key, fallback, required);
    if (!(x > 0.0)) fail(key, "must be > 0");
    return x;
  }
  std::string string(const char* key) const {
    const json& v = at(key);
    if (!v.is_string() || v.get<std::string>().empty()) fail(key, "must be a non-empty string");
    return v.get<std::string>();
  }
  bool boolean(const char* key, bool fallback) const {
    if (!has(key)) return fallback;
    if (!j_.at(key).is_boolean()) fail(key, "must be true or false");
    return j_.at(key).get<bool>();
  }
  std::uint8_t node_id(const json& v, const std::string& key) const {
    if (!v.is_number_integer() || v.get<long long>() < 1 || v.get<long long>() > 127) {
      fail(key, "must be a CANopen node id 1..127");
    }
    return static_cast<std::uint8_t>(v.get<long long>());
  }

 private:
  const json& j_;
  std::string source_;
  std::string path_;
};

}  // namespace

const char* to_string(LoopMode mode) { return mode == LoopMode::lockstep ? "lockstep" : "realtime"; }

std::int64_t EndcapAppConfig::period_ns() const { return static_cast<std::int64_t>(std::llround(1e9 / loop_rate_hz)); }

EndcapAppConfig parse_config(const std::string& json_text, int endcap_id, const std::string& source) {
  json doc;
  try {
    doc = json::parse(json_text);
  } catch (const json::exception& e) {
    throw ConfigError(source + ": not valid JSON: " + e.what());
  }
  const Reader top(doc, source, "");
  top.only({"format", "bus", "nodes", "spool", "limits", "initial_rest_length_m", "storage_dir", "loop", "timeouts",
            "start_on_boot", "stats_log_period_s"});
  if (top.string("format") != "tensegrity-endcap/1") top.fail("format", "expected \"tensegrity-endcap/1\"");

  EndcapAppConfig c;
  if (endcap_id < 0 || endcap_id > 11) throw ConfigError("--id: end cap id must be 0..11, not " + std::to_string(endcap_id));
  c.endcap_id = endcap_id;

  c.bus = top.string("bus");
  CanBusSpec spec;
  std::string error;
  if (!parse_can_bus_spec(c.bus, spec, error)) top.fail("bus", error);

  const Reader nodes = top.object("nodes");
  nodes.only({"drives", "load_cell"});
  const json& drives = nodes.at("drives");
  if (!drives.is_array() || drives.empty() || drives.size() > core::kMaxMotorsPerEndcap) {
    nodes.fail("drives", "must list 1.." + std::to_string(core::kMaxMotorsPerEndcap) + " drive node ids, one per motor");
  }
  c.motor_count = static_cast<std::uint32_t>(drives.size());
  std::set<int> seen;
  for (std::size_t i = 0; i < drives.size(); ++i) {
    const std::string key = "drives[" + std::to_string(i) + "]";
    c.drive_node_ids[i] = nodes.node_id(drives[i], key);
    if (!seen.insert(c.drive_node_ids[i]).second) nodes.fail(key, "node id used twice");
  }
  if (nodes.has("load_cell") && nodes.at("load_cell").is_null()) {
    c.use_load_cell = false;
  } else {
    c.load_cell_node_id = nodes.node_id(nodes.at("load_cell"), "load_cell");
    if (!seen.insert(c.load_cell_node_id).second) nodes.fail("load_cell", "node id used by a drive too");
    if (c.motor_count > 2) nodes.fail("drives", "the load cell has two channels: at most two motors");
  }

  const Reader spool = top.object("spool");
  spool.only({"radius_m", "counts_per_rev"});
  c.spool_radius_m = spool.positive("radius_m", 0, true);
  c.counts_per_rev = spool.positive("counts_per_rev", 0, true);

  const Reader limits = top.object("limits");
  limits.only({"min_rest_length_m", "max_rest_length_m", "speed_m_per_s", "cutoff_tension_n", "hard_limit_tension_n"});
  core::MotorLimits& l = c.limits;
  l.min_rest_length_m = limits.positive("min_rest_length_m", 0, true);
  l.max_rest_length_m = limits.positive("max_rest_length_m", 0, true);
  l.speed_m_per_s = limits.positive("speed_m_per_s", 0, true);
  l.cutoff_tension_n = limits.positive("cutoff_tension_n", 0, true);
  l.hard_limit_tension_n = limits.positive("hard_limit_tension_n", 0, true);
  if (!(l.max_rest_length_m > l.min_rest_length_m)) limits.fail("max_rest_length_m", "must be above min_rest_length_m");
  if (!(l.hard_limit_tension_n >= l.cutoff_tension_n)) {
    limits.fail("hard_limit_tension_n", "must be at least cutoff_tension_n");
  }

  c.initial_rest_length_m = top.positive("initial_rest_length_m", 0, true);
  if (c.initial_rest_length_m < l.min_rest_length_m || c.initial_rest_length_m > l.max_rest_length_m) {
    top.fail("initial_rest_length_m", "must lie within limits.min_rest_length_m..max_rest_length_m");
  }
  c.storage_dir = top.string("storage_dir");

  if (top.has("loop")) {
    const Reader loop = top.object("loop");
    loop.only({"rate_hz", "mode"});
    c.loop_rate_hz = loop.positive("rate_hz", 1000.0);
    if (c.loop_rate_hz > 10'000.0) loop.fail("rate_hz", "must be at most 10000");
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
  if (top.has("timeouts")) {
    const Reader t = top.object("timeouts");
    t.only({"drive_heartbeat_s", "load_cell_heartbeat_s", "load_cell_sample_s"});
    c.drive_heartbeat_timeout_s = t.positive("drive_heartbeat_s", c.drive_heartbeat_timeout_s);
    c.load_cell_heartbeat_timeout_s = t.positive("load_cell_heartbeat_s", c.load_cell_heartbeat_timeout_s);
    c.load_cell_sample_timeout_s = t.positive("load_cell_sample_s", c.load_cell_sample_timeout_s);
    // A sample timeout shorter than two periods would trip on ordinary jitter.
    if (c.load_cell_sample_timeout_s < 2.0 / c.loop_rate_hz) t.fail("load_cell_sample_s", "must be at least two loop periods");
  }
  c.start_on_boot = top.boolean("start_on_boot", false);
  c.stats_log_period_s = top.positive("stats_log_period_s", c.stats_log_period_s);
  return c;
}

EndcapAppConfig load_config(const std::filesystem::path& path, int endcap_id) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path.string() + ": cannot open the config file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_config(text.str(), endcap_id, path.string());
}

}  // namespace tensegrity::fw::app
