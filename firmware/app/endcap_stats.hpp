// SPDX-License-Identifier: Apache-2.0
// What an end cap program reports about its run (`endcap --stats-json FILE`), as one
// typed schema for the writer (the program) and its readers (the HIL's summary,
// tests): written every second while the program runs, so that a killed end cap
// leaves a snapshot no older than that, and once more, complete, at exit. A
// snapshot's loop counts are those of the loop's last status line (every
// stats_log_period_s); its link events are current.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "firmware/app/host_link.hpp"

namespace tensegrity::fw::app {

class StatsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct TimingStats {
  std::uint64_t count = 0;
  double p50_us = 0.0, p99_us = 0.0, max_us = 0.0;
};

// Where the table stood at the last cycle, so a launcher can check that end caps
// play in phase. Lockstep: the table time at the last SYNC; real time: the
// CLOCK_MONOTONIC reading of loop time 0 (loop_clock_origin_ns) plus origin_loop_ns.
struct TablePhase {
  double period_s = 0.0;
  std::int64_t loop_time_ns = 0;
  std::int64_t table_time_ns = 0;
  std::int64_t origin_loop_ns = 0;
  std::optional<std::int64_t> loop_clock_origin_ns;  // real time only
};

struct EndcapStats {
  // 2: link.rejoins (the end cap's new DDS participants).
  static constexpr const char* kFormat = "tensegrity-endcap-stats/2";
  bool final = false;  // false: a snapshot taken while the program ran
  int endcap = -1;
  std::string mode;  // "realtime" | "lockstep"
  double rate_hz = 0.0;
  std::uint64_t cycles = 0, overruns = 0, stalls = 0, late_wakeups = 0, syncs_received = 0, send_failures = 0,
                rx_drops = 0, drain_limited_cycles = 0;
  std::string fault = "none";  // core::describe(fault)
  std::string bring_up;        // the drives' bring-up step
  long vm_rss_kb = -1;
  LinkEvents link;  // the DDS link's events, counted by the node
  // At exit only: the loop's timing and, when it was playing, the table's phase.
  std::optional<TimingStats> cycle, wakeup_latency;
  std::optional<TablePhase> table;
};

nlohmann::json to_json(const EndcapStats& stats);
// Throws StatsError naming `source` and the field (e.g. "stats.json: link.host_losses: ...").
EndcapStats parse_stats(const nlohmann::json& j, const std::string& source);
EndcapStats load_stats(const std::filesystem::path& path);
// Written beside and renamed over `path`: a reader (or a kill) never sees half a
// file. Not fsynced: a snapshot lost to a power cut is replaced a second later.
// Returns false when the file could not be written.
bool write_stats(const std::filesystem::path& path, const EndcapStats& stats);

}  // namespace tensegrity::fw::app
