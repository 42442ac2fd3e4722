// SPDX-License-Identifier: Apache-2.0
// `tensegrity start [--at +S]`: every end cap starts its table at the same host
// time, so all 12 play in phase (each maps the host time through its time sync).
// Success means playing, not acked: the telemetry after the start time is read back.
#include <algorithm>
#include <cstdio>

#include "cli/commands.hpp"
#include "cli/ground_cli.hpp"
#include "ground/command.hpp"
#include "ground/start_check.hpp"

namespace tensegrity::cli {

void add_start_command(CLI::App& app) {
  struct Args {
    std::string at = "+1";
    bool no_confirm = false;
    double confirm_within_s = 1.0;
    GroundOptions ground;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("start", "Start the uploaded policy on the end caps, in phase");
  cmd->add_option("--at", args->at, "Start time relative to now, '+S' in seconds (0..60)")->capture_default_str();
  cmd->add_option("--confirm-within", args->confirm_within_s,
                  "Seconds after the start time within which every end cap's telemetry must show it playing")
      ->check(CLI::Range(0.1, 30.0))
      ->capture_default_str();
  cmd->add_flag("--no-confirm", args->no_confirm,
                "Return once every end cap acked; do not wait for telemetry to show them playing");
  add_ground_options(*cmd, args->ground, 5.0);
  cmd->callback([args] {
    double delay_s = 0.0;
    try {
      std::size_t used = 0;
      const std::string text = !args->at.empty() && args->at[0] == '+' ? args->at.substr(1) : args->at;
      delay_s = std::stod(text, &used);
      if (used != text.size() || !(delay_s >= 0.0 && delay_s <= 60.0)) throw std::out_of_range(text);
    } catch (const std::exception&) {
      throw CommandError(ExitCode::usage, "--at '" + args->at + "': expected +S with S in 0..60 seconds");
    }
    auto station = make_station(args->ground);
    if (!wait_for_endcaps(*station, args->ground, true)) {
      std::fprintf(stderr, "warning: not every end cap reported a synchronized clock; sending anyway\n");
    }
    const std::int64_t t = ground::Station::now_ns() + static_cast<std::int64_t>(delay_s * 1e9);
    ground::CommandOptions options;
    options.endcap_mask = parse_endcap_set(args->ground.endcaps);
    options.timeout_s = args->ground.timeout_s;
    const ground::CommandReport report = ground::send_command(*station, ground::CommandKind::start, t, options);
    std::printf("start at host time %.3f s (in %.3f s)\n%s", static_cast<double>(t) / 1e9, delay_s,
                ground::format_command_report(report).c_str());
    if (!report.all_accepted()) throw CommandError(ExitCode::failure, "start: not every end cap accepted");
    if (args->no_confirm) return;
    std::printf("waiting up to %.1f s after the start time for telemetry that shows every end cap playing\n",
                args->confirm_within_s);
    std::fflush(stdout);
    // From the start time, or from the last ack when the acks took longer than the lead.
    const std::int64_t deadline =
        std::max(t, ground::Station::now_ns()) + static_cast<std::int64_t>(args->confirm_within_s * 1e9);
    const auto checks = ground::wait_playing(*station, options.endcap_mask, t, deadline);
    std::printf("%s", ground::format_playing(checks).c_str());
    if (!ground::all_playing(checks)) {
      char why[200];
      std::snprintf(why, sizeof why,
                    "start: acked, but not every end cap is playing %.1f s after the start time (look: tensegrity "
                    "status; the others play: tensegrity stop)",
                    args->confirm_within_s);
      throw CommandError(ExitCode::failure, why);
    }
  });
}

}  // namespace tensegrity::cli
