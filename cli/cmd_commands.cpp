// SPDX-License-Identifier: Apache-2.0
// `tensegrity stop`, `estop` and `clear-fault`: one acknowledged command to every
// addressed end cap, a table of who acknowledged, non-zero unless all did. Sent at
// once (no wait for discovery: re-sent until acked), and when acks stop coming
// while end caps are missing, from a fresh participant (ground::send_command_rejoining):
// a stalled DDS Security handshake must not keep an emergency stop from an end cap.
#include <cstdio>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "cli/ground_cli.hpp"
#include "ground/command.hpp"

namespace tensegrity::cli {
namespace {

// A fresh secured tool needs up to ~6 s to authenticate with twelve end caps
// (docs/security.md), one rejoin 4 s more: the defaults leave room for both.
void add_command(CLI::App& app, const std::string& name, const std::string& help, ground::CommandKind kind,
                 double default_timeout_s) {
  auto args = std::make_shared<GroundOptions>();
  CLI::App* cmd = app.add_subcommand(name, help);
  add_ground_options(*cmd, *args, default_timeout_s);
  cmd->callback([args, name, kind] {
    const ground::StationOptions station_opts = station_options(*args);
    auto station = std::make_unique<ground::Station>(station_opts);
    ground::CommandOptions options;
    options.endcap_mask = parse_endcap_set(args->endcaps);
    options.timeout_s = args->timeout_s;
    // The estop is re-sent every kEstopRetryIntervalS to whoever has not acked.
    if (kind == ground::CommandKind::emergency_stop) options.retry_interval_s = ground::kEstopRetryIntervalS;
    ground::RejoinOptions rejoin;
    rejoin.make_station = [station_opts] { return std::make_unique<ground::Station>(station_opts); };
    const ground::CommandReport report = ground::send_command_rejoining(station, kind, 0, options, rejoin);
    std::printf("%s", ground::format_command_report(report).c_str());
    const std::vector<int> missing = report.missing();
    if (!missing.empty()) {
      std::string list;
      for (const int e : missing) list += (list.empty() ? "" : ",") + std::to_string(e);
      throw CommandError(1, name + ": no acknowledgement from end cap(s) " + list + " before the deadline");
    }
    if (!report.all_accepted()) throw CommandError(1, name + ": not every end cap accepted");
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
  add_command(app, "clear-fault", "Clear latched faults; end caps return to idle and must be started again",
              ground::CommandKind::clear_fault, 15.0);
}

}  // namespace tensegrity::cli
