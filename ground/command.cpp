// SPDX-License-Identifier: Apache-2.0
#include "ground/command.hpp"

#include <algorithm>
#include <atomic>
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

namespace {
// A report with a row per addressed end cap, none acknowledged yet.
CommandReport unanswered(CommandKind kind, std::int64_t start_host_time_ns, std::uint16_t endcap_mask) {
  CommandReport report;
  report.kind = kind;
  report.start_host_time_ns = start_host_time_ns;
  for (int e = 0; e < kEndcapCount; ++e) {
    if ((endcap_mask & (1U << e)) == 0) continue;
    EndcapCommandResult r;
    r.endcap = e;
    report.results.push_back(r);
  }
  return report;
}
}  // namespace

CommandReport send_command(Station& station, CommandKind kind, std::int64_t start_host_time_ns,
                           const CommandOptions& options) {
  if (options.endcap_mask == 0 || (options.endcap_mask & ~kAllEndcaps) != 0) {
    throw std::invalid_argument("command: end cap mask must address some of end caps 0..11");
  }
  if (!(options.timeout_s > 0.0) || !(options.retry_interval_s > 0.0)) {
    throw std::invalid_argument("command: timeout and retry interval must be > 0 s");
  }
  // Atomic: a HIL run's supervisor thread and an operator's in the same process
  // (the tests) send commands at once; two equal seqs would share their acks.
  static std::atomic<std::uint32_t> next_seq{random_sequence_base()};
  msg::Command_ cmd;
  cmd.format_version(msgs::kFormatVersion);
  cmd.seq(next_seq.fetch_add(1));
  cmd.kind(static_cast<std::uint8_t>(kind));
  cmd.endcap_mask(options.endcap_mask);
  cmd.start_host_time_ns(start_host_time_ns);
  const std::int64_t begin = Station::now_ns();
  CommandReport report = unanswered(kind, start_host_time_ns, options.endcap_mask);
  if (kind == CommandKind::clear_fault) {
    EstopsSeen own;
    EstopsSeen& seen =
        options.estops_seen ? *options.estops_seen : (own = estops_seen_now(station, options.endcap_mask));
    const std::int64_t send_ns = static_cast<std::int64_t>(std::max(0.0, options.timeout_s - kClearSendS) * 1e9);
    const std::int64_t until =
        std::min(station.started_ns() + static_cast<std::int64_t>(kClearHearWaitS * 1e9), begin + send_ns);
    if (!hear_unknown(station, options.endcap_mask, until, seen, options.keep_going)) {
      report.preempted = true;
      return report;
    }
    seen.write_to(cmd);
  }
  const std::int64_t start = Station::now_ns();
  cmd.issued_host_time_ns(start);

  station.take_command_acks();
  const std::int64_t deadline = begin + static_cast<std::int64_t>(options.timeout_s * 1e9);
  const auto retry_ns = static_cast<std::int64_t>(options.retry_interval_s * 1e9);
  std::size_t outstanding = report.results.size();
  std::int64_t next_send = start;
  // A command that may be preempted waits in short slices so that it yields quickly.
  constexpr std::int64_t kPreemptCheckNs = 20'000'000;
  while (outstanding > 0 && Station::now_ns() < deadline) {
    if (options.keep_going && !options.keep_going()) {
      report.preempted = true;
      break;
    }
    if (Station::now_ns() >= next_send) {
      // The same (issued time, sequence) again: an end cap that already handled it
      // only repeats its ack.
      station.write_command(cmd);
      next_send = Station::now_ns() + retry_ns;
    }
    std::int64_t wake = std::min(next_send, deadline);
    if (options.keep_going) wake = std::min(wake, Station::now_ns() + kPreemptCheckNs);
    station.wait_for_command_acks(wake);
    const std::int64_t arrived = Station::now_ns();
    for (const auto& ack : station.take_command_acks()) {
      if (ack.seq() != cmd.seq()) continue;
      station.note_estops(ack.endcap_id(), {ack.life_id(), ack.estops_received()});
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

CommandReport send_command_rejoining(std::unique_ptr<Station>& station, CommandKind kind,
                                     std::int64_t start_host_time_ns, const CommandOptions& options,
                                     const RejoinOptions& rejoin) {
  if (!(rejoin.stall_s > 0.0) || !rejoin.make_station) {
    throw std::invalid_argument("command: rejoin needs a stall time > 0 s and a way to make a station");
  }
  const std::int64_t start = Station::now_ns();
  const std::int64_t deadline = start + static_cast<std::int64_t>(options.timeout_s * 1e9);
  CommandReport report = unanswered(kind, start_host_time_ns, options.endcap_mask);
  std::uint16_t missing = options.endcap_mask;
  // One view for every slice: a later participant must not name estops taken since.
  std::shared_ptr<EstopsSeen> seen = options.estops_seen;
  if (kind == CommandKind::clear_fault && !seen) {
    seen = std::make_shared<EstopsSeen>(estops_seen_now(*station, options.endcap_mask));
  }
  for (;;) {
    // One slice: until the missing end caps acked, the deadline, or stall_s passed.
    const std::int64_t slice_start = Station::now_ns();
    CommandOptions slice = options;
    slice.endcap_mask = missing;
    slice.estops_seen = seen;
    // A clear-fault first waits to hear end caps it does not know yet, while its
    // station is young (send_command): the stall clock starts after that.
    const std::int64_t young_until = station->started_ns() + static_cast<std::int64_t>(kClearHearWaitS * 1e9);
    const double hear_s = kind == CommandKind::clear_fault && !seen->all_known(missing)
                              ? std::max(0.0, static_cast<double>(young_until - slice_start) / 1e9)
                              : 0.0;
    slice.timeout_s = std::min(rejoin.stall_s + hear_s, static_cast<double>(deadline - slice_start) / 1e9);
    if (!(slice.timeout_s > 0.0)) return report;
    bool progress = false;
    const CommandReport got_slice = send_command(*station, kind, start_host_time_ns, slice);
    for (const EndcapCommandResult& got : got_slice.results) {
      if (!got.acked) continue;
      for (EndcapCommandResult& r : report.results) {
        if (r.endcap != got.endcap) continue;
        r = got;  // its latency from the first send, not the slice's
        r.latency_s += static_cast<double>(slice_start - start) / 1e9;
      }
      missing = static_cast<std::uint16_t>(missing & ~(1U << got.endcap));
      progress = true;
    }
    report.preempted = got_slice.preempted;
    if (missing == 0 || report.preempted || Station::now_ns() >= deadline) return report;
    if (!progress) {
      station.reset();  // the stalled participant goes first, with its sockets
      station = rejoin.make_station();
      ++report.rejoins;
    }
  }
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
  if (report.preempted) out += "ended early: an emergency stop took over, or the console stopped\n";
  if (report.rejoins > 0) {
    out += "rejoined the DDS domain " + std::to_string(report.rejoins) + " time(s) (stalled security handshakes)\n";
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
