// SPDX-License-Identifier: Apache-2.0
// Operator commands with per-end-cap acknowledgement (start, stop, emergency stop,
// clear fault), sent again until every addressed end cap answered.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "firmware/comms/wire/reasons.hpp"
#include "ground/estops_seen.hpp"
#include "ground/station.hpp"

namespace tensegrity::ground {

enum class CommandKind : std::uint8_t { start = 0, stop = 1, emergency_stop = 2, clear_fault = 3 };
const char* to_string(CommandKind kind);

struct CommandOptions {
  std::uint16_t endcap_mask = kAllEndcaps;
  double timeout_s = 5.0;         // the deadline: end caps silent until then are reported missing
  double retry_interval_s = 0.5;  // re-sent (same seq) to every end cap that has not acked
  // When set, asked every few milliseconds: false ends the command early (an
  // operator station's emergency stop preempts a stop or clear-fault in flight).
  std::function<bool()> keep_going;
  // Clear-fault: the end caps' estop counts as the operator's tool had heard them
  // when asked (ground/estops_seen.hpp); end caps unknown there are filled in as they
  // are first heard. Null: taken from the station when send_command starts.
  std::shared_ptr<EstopsSeen> estops_seen;
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
  int rejoins = 0;         // send_command_rejoining: fresh participants it took
  bool preempted = false;  // ended early by options.keep_going
  bool all_accepted() const;
  std::vector<int> missing() const;  // addressed end caps that never acknowledged
};

// `start_host_time_ns` (host clock, Station::now_ns) is used by start only.
// A clear-fault names, per end cap, the emergency stops the tool had heard it take
// (options.estops_seen); an end cap that has taken one since refuses it. An end cap
// not yet heard is waited for until kClearHearWaitS after the station was made (a
// fresh secured tool needs ~6 s to authenticate with twelve; a long-running console
// does not wait), leaving kClearSendS of the timeout to send; one still unheard then
// refuses the clear.
inline constexpr double kClearHearWaitS = 8.0;
inline constexpr double kClearSendS = 2.0;
CommandReport send_command(Station& station, CommandKind kind, std::int64_t start_host_time_ns,
                           const CommandOptions& options);

// For a command that must land (the emergency stop): a secured participant's
// handshake with an end cap now and then stalls for good in Fast DDS 2.9
// (docs/guide/security.md), and a fresh ground tool needs seconds to authenticate with
// twelve. While end caps are missing and none has acknowledged for `stall_s`, the
// station is replaced by a new one from `make_station` (a new participant,
// handshakes afresh) and the command goes on until all acked or the deadline.
struct RejoinOptions {
  double stall_s = 4.0;
  std::function<std::unique_ptr<Station>()> make_station;
};
CommandReport send_command_rejoining(std::unique_ptr<Station>& station, CommandKind kind,
                                     std::int64_t start_host_time_ns, const CommandOptions& options,
                                     const RejoinOptions& rejoin);

std::string format_command_report(const CommandReport& report);

}  // namespace tensegrity::ground
