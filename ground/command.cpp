// SPDX-License-Identifier: Apache-2.0
#include "ground/command.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "ground/upload.hpp"
#include "msgs/dds.hpp"

namespace tensegrity::ground {

const char* to_string(CommandKind kind) {
  switch (kind) {
    case CommandKind::start: return "start";
    case CommandKind::stop: return "stop";
    case CommandKind::emergency_stop: return "estop";
    case CommandKind::clear_fault: return "clear-fault";
  }
  return "unknown";
}

bool CommandReport::all_accepted() const {
  return !results.empty() && std::all_of(results.begin(), results.end(), [](const auto& r) { return r.accepted; });
}

std::vector<int> CommandReport::missing() const {
  std::vector<int> out;
  for (const auto& r : results) {
    if (!r.acked) out.push_back(r.endcap);
  }
  return out;
}

CommandReport send_command(Station& station, CommandKind kind, std::int64_t start_host_time_ns,
                           const CommandOptions& options) {
  if (options.endcap_mask == 0 || (options.endcap_mask & ~kAllEndcaps) != 0) {
    throw std::invalid_argument("command: end cap mask must address some of end caps 0..11");
  }
  if (!(options.timeout_s > 0.0) || !(options.retry_interval_s > 0.0)) {
    throw std::invalid_argument("command: timeout and retry interval must be > 0 s");
  }
  static std::uint32_t next_seq = random_sequence_base();
  msg::Command_ cmd;
  cmd.format_version(msgs::kFormatVersion);
  cmd.seq(next_seq++);
  cmd.kind(static_cast<std::uint8_t>(kind));
  cmd.endcap_mask(options.endcap_mask);
  cmd.start_host_time_ns(start_host_time_ns);
  const std::int64_t start = Station::now_ns();
  cmd.issued_host_time_ns(start);

  CommandReport report;
  report.kind = kind;
  report.start_host_time_ns = start_host_time_ns;
  for (int e = 0; e < kEndcapCount; ++e) {
    if ((options.endcap_mask & (1U << e)) == 0) continue;
    EndcapCommandResult r;
    r.endcap = e;
    report.results.push_back(r);
  }
  station.take_command_acks();
  const std::int64_t deadline = start + static_cast<std::int64_t>(options.timeout_s * 1e9);
  const auto retry_ns = static_cast<std::int64_t>(options.retry_interval_s * 1e9);
  std::size_t outstanding = report.results.size();
  std::int64_t next_send = start;
  while (outstanding > 0 && Station::now_ns() < deadline) {
    if (Station::now_ns() >= next_send) {
      // The same (issued time, sequence) again: an end cap that already handled it
      // only repeats its ack.
      station.write_command(cmd);
      next_send = Station::now_ns() + retry_ns;
    }
    station.wait_for_acks(std::min(next_send, deadline));
    const std::int64_t arrived = Station::now_ns();
    for (const auto& ack : station.take_command_acks()) {
      if (ack.seq() != cmd.seq()) continue;
      for (auto& r : report.results) {
        if (r.endcap != ack.endcap_id() || r.acked) continue;
        r.acked = true;
        r.accepted = ack.accepted();
        r.reason = static_cast<fw::comms::CommandReason>(ack.reason());
        r.text = ack.reason_text().to_string();
        r.latency_s = static_cast<double>(arrived - start) / 1e9;
        --outstanding;
      }
    }
  }
  return report;
}

std::string format_command_report(const CommandReport& report) {
  std::string out = "endcap  result    latency_ms  reason\n";
  char line[256];
  for (const auto& r : report.results) {
    const char* result = !r.acked ? "MISSING" : r.accepted ? "accepted" : "REJECTED";
    std::snprintf(line, sizeof line, "%6d  %-8s  %10.1f  %s\n", r.endcap, result, r.acked ? r.latency_s * 1e3 : 0.0,
                  r.text.c_str());
    out += line;
  }
  const std::vector<int> missing = report.missing();
  if (!missing.empty()) {
    out += "no acknowledgement from end cap(s):";
    for (const int e : missing) out += " " + std::to_string(e);
    out += "\n";
  }
  return out;
}

}  // namespace tensegrity::ground
