// SPDX-License-Identifier: Apache-2.0
// `tensegrity stop`, `estop` and `clear-fault`: one acknowledged command to every
// addressed end cap, a table of who acknowledged, non-zero unless all did.
#include <cstdio>
#include <string>

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
    wait_for_endcaps(*station, *args, false);  // a missing end cap shows as MISSING below
    ground::CommandOptions options;
    options.endcap_mask = parse_endcap_set(args->endcaps);
    options.timeout_s = args->timeout_s;
    const ground::CommandReport report = ground::send_command(*station, kind, 0, options);
    std::printf("%s", ground::format_command_report(report).c_str());
    if (!report.all_accepted()) throw CommandError(1, name + ": not every end cap acknowledged");
  });
}

}  // namespace

void add_stop_command(CLI::App& app) {
  add_command(app, "stop", "Stop the gait: every end cap holds its current rest lengths", ground::CommandKind::stop);
}

void add_estop_command(CLI::App& app) {
  add_command(app, "estop", "Emergency stop: every end cap latches a fault and holds until cleared",
              ground::CommandKind::emergency_stop);
}

void add_clear_fault_command(CLI::App& app) {
  add_command(app, "clear-fault", "Clear latched faults; end caps return to idle and must be started again",
              ground::CommandKind::clear_fault);
}

}  // namespace tensegrity::cli
