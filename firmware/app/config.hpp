// SPDX-License-Identifier: Apache-2.0
// The end cap program's configuration file (format "tensegrity-endcap/1"), parsed
// once at start-up. Every error names the file and the field, so a typo in the
// field is found from the log line alone. Unknown fields are errors for the same
// reason: a misspelt limit must not silently fall back to its default.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "core/loop_period.hpp"
#include "core/limits.hpp"
#include "firmware/drivers/cia402.hpp"
#include "firmware/drivers/spool_geometry.hpp"

namespace tensegrity::fw::app {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class LoopMode : std::uint8_t {
  realtime,  // own absolute-deadline timer every period_ns; the end cap sends SYNC
  lockstep,  // one cycle per SYNC received from the bus (the HIL owns time)
};

const char* to_string(LoopMode mode);

struct EndcapAppConfig {
  int endcap_id = 0;  // 0..11, from --id (not in the file: one file may serve a test rig)
  std::string bus;    // "socketcan:can0" | "udp:HOST:PORT[,bind=HOST:PORT]"
  // One drive per motor, in motor order; the load cell's channel m measures motor m.
  std::uint32_t motor_count = 2;
  std::array<std::uint8_t, core::kMaxMotorsPerEndcap> drive_node_ids{1, 3, 0, 0};
  std::uint8_t load_cell_node_id = 2;
  // The tension guard (cut-off and hard limit) from the load cell's readings; off
  // only by "tension_guard": "off" (no load cell), warned about at every start.
  bool use_load_cell = true;
  double spool_radius_m = SpoolGeometry{}.spool_radius_m;
  double counts_per_rev = SpoolGeometry{}.counts_per_rev;
  core::MotorLimits limits{};
  double initial_rest_length_m = 0.95;  // rest length at drive count 0 (homing)
  std::filesystem::path storage_dir = "/var/lib/tensegrity/endcap";
  // The loop's period, which is also the SYNC period and the drives' interpolation
  // period (bring-up writes it to them): core/loop_period.hpp's limits, whole
  // microseconds, and a value 0x60C2 can say.
  std::int64_t loop_period_ns = core::kDefaultLoopPeriodNs;
  LoopMode mode = LoopMode::realtime;
  double drive_heartbeat_timeout_s = 0.1;
  double load_cell_heartbeat_timeout_s = 0.1;
  // No fresh load-cell sample (new sequence number, channel valid) for this long
  // trips sensor_timeout; a few SYNC periods.
  double load_cell_sample_timeout_s = 0.02;
  // Supervision (docs/design/canopen.md "Supervision"). A drive position (TPDO1) older
  // than this trips stale_position; a few SYNC periods.
  double drive_position_timeout_s = 0.02;
  // The end cap's own CANopen node: its heartbeat period (0x1017) and the consumer
  // time each drive watches it with (0x1016); both whole milliseconds. Defaults:
  // 10 ms (or one loop period, if longer) and five producer periods, so one late
  // cycle never trips a drive and a dead end cap is stopped within 50 ms.
  std::uint8_t endcap_node_id = 127;
  double endcap_heartbeat_s = 0.01;
  double drive_consumer_heartbeat_s = 0.05;
  // 0x6007: what a drive does by itself when the end cap's heartbeat stops.
  canopen::AbortConnectionOption drive_abort_connection = canopen::AbortConnectionOption::quick_stop;
  bool start_on_boot = false;
  double stats_log_period_s = 10.0;
  // DDS Security keystore (tensegrity security init; this end cap uses its enclave
  // enclaves/tensegrity/endcap_NN). Empty: not in the file, so `endcap` needs
  // --keystore or an explicit --insecure (docs/guide/security.md).
  std::filesystem::path dds_keystore;

  SpoolGeometry spool() const { return SpoolGeometry{spool_radius_m, counts_per_rev, initial_rest_length_m}; }
};

// Why the loop cannot run at this period ("" when it can): the config's check of
// loop.period_ns, and the HIL's of a robot's step before it launches end caps.
std::string loop_period_problem(std::int64_t period_ns);

// The one writer of the format, beside its one reader: every field, so that
// parse_config(config_to_json_text(c), c.endcap_id) == c. The HIL's launcher
// writes its end caps' files with it instead of spelling the fields itself.
std::string config_to_json_text(const EndcapAppConfig& c);

// `source` names the text in errors (the file path).
EndcapAppConfig parse_config(const std::string& json_text, int endcap_id, const std::string& source = "config");
EndcapAppConfig load_config(const std::filesystem::path& path, int endcap_id);

}  // namespace tensegrity::fw::app
