// SPDX-License-Identifier: Apache-2.0
#include "ground/status.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>

#include "core/fault.hpp"

namespace tensegrity::ground {

const char* mode_name(std::uint8_t mode) {
  switch (mode) {
    case 0: return "idle";
    case 1: return "running";
    case 2: return "faulted";
    default: return "?";
  }
}

const char* fault_name(std::uint8_t fault) {
  switch (static_cast<core::FaultCause>(fault)) {
    case core::FaultCause::none: return "-";
    case core::FaultCause::over_tension: return "over_tension";
    case core::FaultCause::drive_fault: return "drive_fault";
    case core::FaultCause::drive_lost: return "drive_lost";
    case core::FaultCause::sensor_timeout: return "sensor_timeout";
    case core::FaultCause::host_lost: return "host_lost";
    case core::FaultCause::emergency_stop: return "emergency_stop";
    case core::FaultCause::bad_input: return "bad_input";
    case core::FaultCause::node_rebooted: return "node_rebooted";
    case core::FaultCause::drive_disabled: return "drive_disabled";
    case core::FaultCause::stale_position: return "stale_position";
    case core::FaultCause::loop_stalled: return "loop_stalled";
    case core::FaultCause::node_not_operational: return "node_not_operational";
  }
  return "?";
}

namespace {
bool is_expected(std::uint16_t expected, int endcap) { return (expected & (1U << endcap)) != 0; }

double age_s(const EndcapStatus& s, std::int64_t now_ns) {
  return static_cast<double>(now_ns - s.heartbeat_host_ns) / 1e9;
}
bool silent(const EndcapStatus& s, std::int64_t now_ns) { return s.seen && age_s(s, now_ns) > Station::kHeardFreshS; }
}  // namespace

std::vector<int> silent_endcaps(const std::array<EndcapStatus, kEndcapCount>& status, std::int64_t now_ns,
                                std::uint16_t expected) {
  std::vector<int> out;
  for (int e = 0; e < kEndcapCount; ++e) {
    if (is_expected(expected, e) && silent(status[static_cast<std::size_t>(e)], now_ns)) out.push_back(e);
  }
  return out;
}

std::vector<int> missing_endcaps(const std::array<EndcapStatus, kEndcapCount>& status, std::uint16_t expected) {
  std::vector<int> out;
  for (int e = 0; e < kEndcapCount; ++e) {
    if (is_expected(expected, e) && !status[static_cast<std::size_t>(e)].seen) out.push_back(e);
  }
  return out;
}

std::string format_status_table(const std::array<EndcapStatus, kEndcapCount>& status, std::int64_t now_ns,
                                std::uint16_t expected) {
  std::string out =
      "endcap  hb_age_s  policy                    state    fault           tension_n        offset_ms  rtt_ms  "
      "host\n";
  char line[512];
  for (int e = 0; e < kEndcapCount; ++e) {
    if (!is_expected(expected, e)) continue;
    const EndcapStatus& s = status[static_cast<std::size_t>(e)];
    if (!s.seen) {
      std::snprintf(line, sizeof line, "%6d  %8s  (no heartbeat)\n", e, "-");
      out += line;
      continue;
    }
    const auto& hb = s.heartbeat;
    const std::string policy = hb.active_policy_id().size() == 0 ? "-"
                                                                 : hb.active_policy_id().to_string() + " v" +
                                                                       std::to_string(hb.active_policy_version());
    char tensions[64] = "-";
    if (s.have_telemetry) {
      const auto& t = s.telemetry.tension_n();
      std::snprintf(tensions, sizeof tensions, "%.0f/%.0f", t[0], t[1]);
    }
    std::snprintf(line, sizeof line, "%6d  %8.2f  %-24s  %-7s  %-14s  %-15s  %9.3f  %6.3f  %s%s%s\n", e,
                  age_s(s, now_ns), policy.c_str(), mode_name(hb.mode()), fault_name(hb.fault()), tensions,
                  hb.clock_synced() ? static_cast<double>(hb.clock_offset_ns()) / 1e6 : 0.0,
                  hb.clock_synced() ? static_cast<double>(hb.clock_round_trip_ns()) / 1e6 : 0.0,
                  hb.host_lost() ? "LOST" : "ok", silent(s, now_ns) ? "  SILENT" : "", s.reached ? "" : "  UNREACHED");
    out += line;
  }
  return out;
}

std::string format_status_json(const std::array<EndcapStatus, kEndcapCount>& status, std::int64_t now_ns,
                               std::uint16_t expected) {
  nlohmann::json endcaps = nlohmann::json::array();
  for (int e = 0; e < kEndcapCount; ++e) {
    if (!is_expected(expected, e)) continue;
    const EndcapStatus& s = status[static_cast<std::size_t>(e)];
    nlohmann::json j{{"endcap", e}, {"seen", s.seen}};
    if (s.seen) {
      const auto& hb = s.heartbeat;
      j["heartbeat_age_s"] = age_s(s, now_ns);
      j["heard"] = !silent(s, now_ns);
      j["reached"] = s.reached;  // our writers match its readers: a command would land
      j["active_policy"] = hb.active_policy_id().to_string();
      j["active_policy_version"] = hb.active_policy_version();
      j["state"] = mode_name(hb.mode());
      j["fault"] = fault_name(hb.fault());
      j["clock_synced"] = hb.clock_synced();
      j["clock_offset_s"] = static_cast<double>(hb.clock_offset_ns()) / 1e9;
      j["clock_round_trip_s"] = static_cast<double>(hb.clock_round_trip_ns()) / 1e9;
      j["host_lost"] = hb.host_lost();
      j["loop_overruns"] = hb.loop_overruns();
      j["estops_received"] = s.estops.count;  // what a clear-fault from here would name
    }
    if (s.have_telemetry) {
      const auto& t = s.telemetry;
      const std::size_t n = std::min<std::size_t>(t.motor_count(), 4);
      j["tension_n"] = std::vector<double>(t.tension_n().begin(), t.tension_n().begin() + static_cast<long>(n));
      j["commanded_rest_length_m"] = std::vector<double>(t.commanded_rest_length_m().begin(),
                                                         t.commanded_rest_length_m().begin() + static_cast<long>(n));
      j["telemetry_samples"] = s.telemetry_count;
      j["telemetry_gaps"] = s.telemetry_gaps;
    }
    endcaps.push_back(j);
  }
  // The policy ids are the end caps' bytes: one that is not UTF-8 is shown replaced
  // (U+FFFD) instead of throwing out of `tensegrity status --json`.
  return nlohmann::json{{"endcaps", endcaps},
                        {"missing", missing_endcaps(status, expected)},
                        {"silent", silent_endcaps(status, now_ns, expected)}}
      .dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace tensegrity::ground
