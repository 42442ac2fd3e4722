// SPDX-License-Identifier: Apache-2.0
// `tensegrity stop`, `estop` and `clear-fault`: one acknowledged command to every
// addressed end cap, a table of who acknowledged, non-zero unless all did. Sent at
// once (no wait for discovery: re-sent until acked), and when acks stop coming
// while end caps are missing, from a fresh participant (ground::send_command_rejoining):
// a stalled DDS Security handshake must not keep an emergency stop from an end cap.
// When an operator console (`tensegrity console`) runs for the domain, the command
// goes through it instead: its station is already authenticated with the end caps,
// so a secured estop lands in milliseconds rather than after seconds of handshakes.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "cli/ground_cli.hpp"
#include "ground/command.hpp"
#include "ground/operator_client.hpp"
#include "msgs/dds.hpp"

namespace tensegrity::cli {
namespace {

struct CommandArgs {
  GroundOptions ground;
  std::string console;  // empty: ground::default_console_socket(domain)
  bool no_console = false;
};

void check_report(const std::string& name, const ground::CommandReport& report) {
  std::printf("%s", ground::format_command_report(report).c_str());
  const std::vector<int> missing = report.missing();
  if (!missing.empty()) {
    std::string list;
    for (const int e : missing) list += (list.empty() ? "" : ",") + std::to_string(e);
    throw CommandError(ExitCode::failure,
                       name + ": no acknowledgement from end cap(s) " + list + " before the deadline");
  }
  if (!report.all_accepted()) throw CommandError(ExitCode::failure, name + ": not every end cap accepted");
}

// A console exists but did not send the command. A stop or estop then goes out from
// this tool; a clear-fault does not: this tool's fresh participant would name the
// estop counts it hears now, which may include an estop the console saw land since
// the operator asked, and undo it (docs/design/dds.md, clear-fault).
bool speak_instead(const std::string& name, const CommandArgs& args, ground::CommandKind kind,
                   const std::filesystem::path& socket, const std::string& why) {
  if (!args.console.empty()) throw CommandError(ExitCode::failure, name + ": the console did not send it: " + why);
  if (kind == ground::CommandKind::clear_fault) {
    throw CommandError(ExitCode::failure,
                       name + ": the console at " + socket.string() + " did not send it (" + why +
                           "); not sent: look at the end caps (tensegrity status), then clear again (or "
                           "--no-console)");
  }
  std::fprintf(stderr, "%s: the console at %s did not send it (%s); sending on this tool's own participant\n",
               name.c_str(), socket.c_str(), why.c_str());
  return false;
}

// True when a console ran the command (its report checked); false when none listens.
bool through_console(const std::string& name, const CommandArgs& args, ground::CommandKind kind) {
  if (args.no_console) return false;
  const int domain = args.ground.domain >= 0 ? args.ground.domain : msgs::domain_id();
  const std::filesystem::path socket =
      args.console.empty() ? ground::default_console_socket(domain) : std::filesystem::path(args.console);
  ground::OperatorRequest request;
  request.kind = kind;
  request.endcap_mask = parse_endcap_set(args.ground.endcaps);
  request.timeout_s = std::min(args.ground.timeout_s, ground::kMaxOperatorTimeoutS);
  std::optional<ground::OperatorReply> reply;
  try {
    reply = ground::ask_console(socket, request);
  } catch (const ground::OperatorLinkError& e) {
    // A console named with --console must answer; a broken default one must not
    // keep a stop from going out: the tool then speaks itself.
    return speak_instead(name, args, kind, socket, std::string("it did not answer properly: ") + e.what());
  }
  if (!reply) {
    if (!args.console.empty())
      throw CommandError(ExitCode::failure, name + ": no console listens at " + socket.string());
    return false;
  }
  const bool none_acked = reply->report.missing().size() == reply->report.results.size();
  std::uint16_t reported = 0;
  for (const auto& r : reply->report.results) reported = static_cast<std::uint16_t>(reported | (1U << r.endcap));
  if (reply->error.empty() && (reported & request.endcap_mask) != request.endcap_mask) {
    reply->error = "its report leaves out end caps this command addresses";
  }
  if (!reply->error.empty() || (reply->report.preempted && none_acked)) {
    // Refused (busy, stopping) or ended before any end cap answered (an estop took
    // over, or the console is stopping): the command may not have gone out.
    const std::string why = reply->error.empty() ? "it stopped before any end cap answered" : reply->error;
    return speak_instead(name, args, kind, socket, why);
  }
  if (reply->report.preempted) {
    std::fprintf(stderr, "%s: an emergency stop sent after it took over%s\n", name.c_str(),
                 kind == ground::CommandKind::emergency_stop ? " and goes on to the end caps still missing here" : "");
  }
  std::fprintf(stderr, "%s: sent by the console at %s (pid %ld) with its station's identity\n", name.c_str(),
               socket.c_str(), reply->console_pid);
  check_report(name, reply->report);
  return true;
}

// A fresh secured tool needs up to ~6 s to authenticate with twelve end caps
// (docs/guide/security.md), one rejoin 4 s more: the defaults leave room for both. A
// clear-fault waits up to 8 s to hear each end cap before it sends (again after a
// rejoin): 30 s leaves room for one.
void add_command(CLI::App& app, const std::string& name, const std::string& help, ground::CommandKind kind,
                 double default_timeout_s) {
  auto args = std::make_shared<CommandArgs>();
  CLI::App* cmd = app.add_subcommand(name, help);
  add_ground_options(*cmd, args->ground, default_timeout_s);
  auto* console = cmd->add_option("--console", args->console,
                                  "Send through the operator console listening at this socket (default: the "
                                  "domain's console if one runs, see `tensegrity console`; else a participant "
                                  "of this tool's own)");
  cmd->add_flag("--no-console", args->no_console, "Speak on this tool's own DDS participant even if a console runs")
      ->excludes(console);
  cmd->callback([args, name, kind] {
    // The operator asks now; this tool's participant hears the end caps seconds later,
    // and an estop another tool lands meanwhile must not be cleared (docs: clear-fault).
    const auto asked = std::make_shared<ground::EstopsSeen>(ground::estops_asked_now());
    if (through_console(name, *args, kind)) return;
    const ground::StationOptions station_opts = station_options(args->ground);
    auto station = std::make_unique<ground::Station>(station_opts);
    ground::CommandOptions options;
    if (kind == ground::CommandKind::clear_fault) options.estops_seen = asked;
    options.endcap_mask = parse_endcap_set(args->ground.endcaps);
    options.timeout_s = args->ground.timeout_s;
    // The estop is re-sent every kEstopRetryIntervalS to whoever has not acked.
    if (kind == ground::CommandKind::emergency_stop) options.retry_interval_s = ground::kEstopRetryIntervalS;
    ground::RejoinOptions rejoin;
    rejoin.make_station = [station_opts] { return std::make_unique<ground::Station>(station_opts); };
    check_report(name, ground::send_command_rejoining(station, kind, 0, options, rejoin));
  });
}

}  // namespace

void add_stop_command(CLI::App& app) {
  add_command(app, "stop", "Stop the gait: every end cap holds its current rest lengths", ground::CommandKind::stop,
              15.0);
}

void add_estop_command(CLI::App& app) {
  add_command(app, "estop",
              "Emergency stop: every end cap latches a fault and holds until cleared; re-sent every 50 ms until all "
              "addressed end caps acked or --timeout passed (exit 1 naming the silent ones); rejoins the domain "
              "when acks stop coming",
              ground::CommandKind::emergency_stop, 30.0);
}

void add_clear_fault_command(CLI::App& app) {
  add_command(app, "clear-fault",
              "Clear latched faults; end caps return to idle and must be started again. Waits (up to 8 s) to hear "
              "each end cap first; one that took an emergency stop this tool had not heard of refuses "
              "(estop_unseen): look again, then clear",
              ground::CommandKind::clear_fault, 30.0);
}

}  // namespace tensegrity::cli
