// SPDX-License-Identifier: Apache-2.0
// `tensegrity stop`, `estop` and `clear-fault`: one acknowledged command to every
// addressed end cap, a table of who acknowledged, non-zero unless all did.
#include <cstdio>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "cli/ground_cli.hpp"
#include "ground/command.hpp"

namespace tensegrity::cli {
namespace {

void add_command(CLI::App& app, const std::string& name, const std::string& help, ground::CommandKind kind) {
  auto args = std::make_shared<GroundOptions>();
  CLI::App* cmd = app.add_subcommand(name, help);
  add_ground_options(*cmd, *args, 5.0);
  cmd->callback([args, name, kind] {
    auto station = make_station(*args);
    ground::CommandOptions options;
    options.endcap_mask = parse_endcap_set(args->endcaps);
    options.timeout_s = args->timeout_s;
    if (kind == ground::CommandKind::emergency_stop) {
      // No wait for discovery: the estop is written at once and re-sent every
      // kEstopRetryIntervalS to whoever has not acked, until the deadline.
      options.retry_interval_s = ground::kEstopRetryIntervalS;
    } else {
      wait_for_endcaps(*station, *args, false);  // a missing end cap shows as MISSING below
    }
    const ground::CommandReport report = ground::send_command(*station, kind, 0, options);
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
  add_command(app, "stop", "Stop the gait: every end cap holds its current rest lengths", ground::CommandKind::stop);
}

void add_estop_command(CLI::App& app) {
  add_command(app, "estop",
              "Emergency stop: every end cap latches a fault and holds until cleared; re-sent every 50 ms until all "
              "addressed end caps acked or --timeout passed (exit 1 naming the silent ones)",
              ground::CommandKind::emergency_stop);
}

void add_clear_fault_command(CLI::App& app) {
  add_command(app, "clear-fault", "Clear latched faults; end caps return to idle and must be started again",
              ground::CommandKind::clear_fault);
}

}  // namespace tensegrity::cli
