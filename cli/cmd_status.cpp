// SPDX-License-Identifier: Apache-2.0
// `tensegrity status`: a live table of the end caps (heartbeat age, active policy,
// state, fault, tensions, clock offset); --once for one snapshot, --json for tools.
// Both show the end caps of --endcaps only; --once exits 1 when one of them sent
// no heartbeat within --timeout (a script can tell a missing end cap from a
// quiet one), after printing the snapshot with the missing ones marked.
#include <chrono>
#include <cstdio>
#include <thread>
#include <vector>

#include "cli/commands.hpp"
#include "cli/ground_cli.hpp"
#include "ground/status.hpp"

namespace tensegrity::cli {

void add_status_command(CLI::App& app) {
  struct Args {
    bool once = false;
    bool json = false;
    double period_s = 0.5;
    GroundOptions ground;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("status", "Show the end caps' state, live");
  cmd->add_flag("--once", args->once, "Print one snapshot (after --timeout seconds of listening) and exit");
  cmd->add_flag("--json", args->json, "JSON instead of a table");
  cmd->add_option("--period", args->period_s, "Refresh period in seconds")->check(CLI::Range(0.05, 60.0));
  add_ground_options(*cmd, args->ground, 3.0);
  cmd->callback([args] {
    const std::uint16_t expected = parse_endcap_set(args->ground.endcaps);  // a bad set fails before DDS starts
    // Live status is a host: its heartbeat keeps the end caps' host watchdog fed.
    auto station = make_station(args->ground, /*publish_heartbeat=*/!args->once);
    auto print = [&] {
      const auto snap = station->snapshot();
      const std::int64_t now = ground::Station::now_ns();
      const std::string text = args->json ? ground::format_status_json(snap, now, expected) + "\n"
                                          : ground::format_status_table(snap, now, expected);
      std::fputs(text.c_str(), stdout);
      std::fflush(stdout);
      std::vector<int> unheard = ground::missing_endcaps(snap, expected);
      // Heard while listening, then silent: dead or cut off since.
      for (const int e : ground::silent_endcaps(snap, now, expected)) unheard.push_back(e);
      return unheard;
    };
    if (args->once) {
      wait_for_endcaps(*station, args->ground, false);
      std::this_thread::sleep_for(std::chrono::milliseconds(300));  // telemetry too
      const std::vector<int> missing = print();
      if (!missing.empty()) {
        std::string list;
        for (const int e : missing) list += (list.empty() ? "" : ",") + std::to_string(e);
        char text[200];
        std::snprintf(text, sizeof text,
                      "status: no heartbeat (or none for %.0f s) within %.1f s from end cap(s) %s of --endcaps %s",
                      ground::Station::kHeardFreshS, args->ground.timeout_s, list.c_str(),
                      args->ground.endcaps.c_str());
        throw CommandError(ExitCode::failure, text);
      }
      return;
    }
    for (;;) {
      if (!args->json) std::fputs("\033[H\033[2J", stdout);  // clear screen: a live table
      print();
      std::this_thread::sleep_for(std::chrono::duration<double>(args->period_s));
    }
  });
}

}  // namespace tensegrity::cli
