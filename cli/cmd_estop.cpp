// SPDX-License-Identifier: Apache-2.0
// `tensegrity estop`: Emergency stop: every end cap latches a fault and holds until cleared.
#include <cstdio>

#include "cli/commands.hpp"
#include "cli/ground_cli.hpp"
#include "ground/command.hpp"

namespace tensegrity::cli {

void add_estop_command(CLI::App& app) {
  auto args = std::make_shared<GroundOptions>();
  CLI::App* cmd = app.add_subcommand("estop", "Emergency stop: every end cap latches a fault and holds until cleared");
  add_ground_options(*cmd, *args, 5.0);
  cmd->callback([args] {
    auto station = make_station(*args);
    wait_for_endcaps(*station, *args, false);  // a missing end cap shows as MISSING below
    ground::CommandOptions options;
    options.endcap_mask = parse_endcap_set(args->endcaps);
    options.timeout_s = args->timeout_s;
    const ground::CommandReport report = ground::send_command(*station, ground::CommandKind::emergency_stop, 0, options);
    std::printf("%s", ground::format_command_report(report).c_str());
    if (!report.all_accepted()) throw CommandError(1, "estop: not every end cap acknowledged");
  });
}

}  // namespace tensegrity::cli
