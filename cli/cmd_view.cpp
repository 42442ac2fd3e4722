// SPDX-License-Identifier: Apache-2.0
// `tensegrity view`: a local web page of a recorded run, of the end caps live over
// DDS, or of an evolution (view/, docs/guide/view.md).
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <thread>

#include "cli/commands.hpp"
#include "cli/episode_cli.hpp"
#include "cli/ground_cli.hpp"
#include "cli/view_options.hpp"
#include "msgs/dds.hpp"
#include "view/csv_table.hpp"
#include "view/modes.hpp"

namespace tensegrity::cli {
namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_view_signal(int) { g_stop = true; }

struct ViewArgs {
  std::string run_csv;
  bool live = false;
  std::string evolve_dir;
  std::string robot;
  int domain = -1;
  std::string keystore;
  bool insecure = false;
  ViewServerArgs server;
};

void wait_for_signal() {
  std::signal(SIGINT, on_view_signal);
  std::signal(SIGTERM, on_view_signal);
  while (!g_stop) std::this_thread::sleep_for(std::chrono::milliseconds(100));
}

void run_view(const ViewArgs& a) {
  const int modes = (a.run_csv.empty() ? 0 : 1) + (a.live ? 1 : 0) + (a.evolve_dir.empty() ? 0 : 1);
  if (modes != 1) throw CommandError(ExitCode::usage, "view: give one of RUN.csv, --live or --evolve DIR");
  const view::ServerOptions server = to_server_options(a.server);
  try {
    if (!a.run_csv.empty()) {
      const auto started = std::chrono::steady_clock::now();
      view::ReplayView v(a.run_csv, load_robot_arg(a.robot), server);
      for (const auto& w : v.warnings()) std::fprintf(stderr, "tensegrity: warning: %s\n", w.c_str());
      std::printf("view: replay of %s (%zu frames, read in %.2f s) at %s  (Ctrl-C to stop)\n", a.run_csv.c_str(),
                  v.frames(), std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(),
                  v.url().c_str());
      std::fflush(stdout);
      wait_for_signal();
    } else if (a.live) {
      const int domain = a.domain >= 0 ? a.domain : msgs::domain_id();
      view::LiveView v(load_robot_arg(a.robot), domain, server,
                       tool_enclave(msgs::Role::listener, a.keystore, a.insecure));
      std::printf("view: live, DDS domain %d, at %s  (read-only; Ctrl-C to stop)\n", domain, v.url().c_str());
      std::fflush(stdout);
      wait_for_signal();
    } else {
      view::EvolveView v(a.evolve_dir, a.robot, server);
      std::printf("view: evolution in %s at %s  (Ctrl-C to stop)\n", a.evolve_dir.c_str(), v.url().c_str());
      std::fflush(stdout);
      wait_for_signal();
    }
  } catch (const view::InputError& e) {
    throw CommandError(ExitCode::usage, e.what());
  }
}

}  // namespace

void add_view_command(CLI::App& app) {
  auto args = std::make_shared<ViewArgs>();
  CLI::App* cmd = app.add_subcommand("view", "Watch a run, the end caps live, or an evolution in a web browser");
  cmd->add_option("run", args->run_csv, "Telemetry CSV to replay (tensegrity sim --telemetry, tensegrity hil --record)")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--live", args->live, "The end caps' DDS telemetry and heartbeats, live (read-only)");
  cmd->add_option("--evolve", args->evolve_dir,
                  "An evolution's checkpoint directory (tensegrity evolve --checkpoint DIR)")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--robot", args->robot,
                  "Robot (tension limits, cables); default: robots/superball-paper.json, for --evolve the run's")
      ->check(CLI::ExistingFile);
  cmd->add_option("--domain", args->domain, "--live: DDS domain (default: TENSEGRITY_DOMAIN, else 42)")
      ->check(CLI::Range(0, 232));
  add_security_options(*cmd, args->keystore, args->insecure);
  add_view_server_options(*cmd, args->server);
  cmd->callback([args] { run_view(*args); });
}

}  // namespace tensegrity::cli
