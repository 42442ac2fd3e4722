// SPDX-License-Identifier: Apache-2.0
// `tensegrity stop`: Stop the gait: every end cap holds its current rest lengths.
#include <cstdio>

#include "cli/commands.hpp"
#include "cli/ground_cli.hpp"
#include "ground/command.hpp"

namespace tensegrity::cli {

void add_stop_command(CLI::App& app) {
  auto args = std::make_shared<GroundOptions>();
  CLI::App* cmd = app.add_subcommand("stop", "Stop the gait: every end cap holds its current rest lengths");
  add_ground_options(*cmd, *args, 5.0);
  cmd->callback([args] {
    auto station = make_station(*args);
    wait_for_endcaps(*station, *args, false);  // a missing end cap shows as MISSING below
    ground::CommandOptions options;
    options.endcap_mask = parse_endcap_set(args->endcaps);
    options.timeout_s = args->timeout_s;
    const ground::CommandReport report = ground::send_command(*station, ground::CommandKind::stop, 0, options);
    std::printf("%s", ground::format_command_report(report).c_str());
    if (!report.all_accepted()) throw CommandError(1, "stop: not every end cap acknowledged");
  });
}

}  // namespace tensegrity::cli
