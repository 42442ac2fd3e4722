// SPDX-License-Identifier: Apache-2.0
// Operator commands with per-end-cap acknowledgement (start, stop, emergency stop,
// clear fault), sent again until every addressed end cap answered.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "firmware/comms/reasons.hpp"
#include "ground/station.hpp"

namespace tensegrity::ground {

enum class CommandKind : std::uint8_t { start = 0, stop = 1, emergency_stop = 2, clear_fault = 3 };
const char* to_string(CommandKind kind);

struct CommandOptions {
  std::uint16_t endcap_mask = kAllEndcaps;
  double timeout_s = 5.0;        // the deadline: end caps silent until then are reported missing
  double retry_interval_s = 0.5;  // re-sent (same seq) to every end cap that has not acked
};
// An emergency stop is re-sent more often: each retry is one more chance through a
// lossy link, and an end cap answers a repeat without acting twice.
inline constexpr double kEstopRetryIntervalS = 0.05;

struct EndcapCommandResult {
  int endcap = 0;
  bool acked = false;
  bool accepted = false;
  fw::comms::CommandReason reason = fw::comms::CommandReason::accepted;
  std::string text = "no acknowledgement";
  double latency_s = 0.0;
};

struct CommandReport {
  CommandKind kind = CommandKind::stop;
  std::int64_t start_host_time_ns = 0;
  std::vector<EndcapCommandResult> results;
  bool all_accepted() const;
  std::vector<int> missing() const;  // addressed end caps that never acknowledged
};

// `start_host_time_ns` (host clock, Station::now_ns) is used by start only.
CommandReport send_command(Station& station, CommandKind kind, std::int64_t start_host_time_ns,
                           const CommandOptions& options);

std::string format_command_report(const CommandReport& report);

}  // namespace tensegrity::ground
