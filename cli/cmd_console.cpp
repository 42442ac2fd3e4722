// SPDX-License-Identifier: Apache-2.0
// `tensegrity console`: a long-lived operator station. It joins the DDS domain once
// (authenticating with every end cap when secured), keeps the end caps' host
// heartbeat, shows their state, and sends an emergency stop on a key press (e or
// space), stop (s) and clear fault (c). It also relays those commands for the
// ground tools on this machine through a local socket (ground/operator_server.hpp):
// with a console running, `tensegrity estop` lands in milliseconds instead of after
// a fresh participant's seconds of security handshakes.
#include <atomic>
#include <bit>
#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "cli/commands.hpp"
#include "cli/console_keys.hpp"
#include "cli/ground_cli.hpp"
#include "cli/stop_signals.hpp"
#include "ground/operator_server.hpp"
#include "ground/station_keeper.hpp"
#include "ground/status.hpp"
#include "msgs/dds.hpp"

namespace tensegrity::cli {
namespace {

struct ConsoleArgs {
  GroundOptions ground;
  std::string socket;
  double period_s = 0.5;
};

// Commands from keys run beside the display, one at a time in the server; the
// last report stays on screen. A key estop while one is already on its way is not
// queued again (holding the key must not stack up stops).
class KeyCommands {
 public:
  explicit KeyCommands(ground::OperatorServer& server) : server_(server) {}
  void send(ground::CommandKind kind, std::uint16_t mask, double timeout_s) {
    const bool estop = kind == ground::CommandKind::emergency_stop;
    if (estop && estop_pending_.exchange(true)) return;
    std::erase_if(workers_, [](const Worker& w) { return w.done->load(); });
    auto done = std::make_shared<std::atomic<bool>>(false);
    workers_.push_back({std::jthread([this, kind, mask, timeout_s, estop, done] {
                          std::string text;
                          std::string unsure;  // an estop that may not have reached every end cap
                          try {
                            const ground::CommandReport report = server_.run({kind, mask, timeout_s});
                            text = ground::format_command_report(report);
                            if (estop && !report.preempted && !report.missing().empty()) unsure = "no ack from some";
                          } catch (const std::exception& e) {
                            text = std::string("not sent: ") + e.what() + "\n";
                            if (estop) unsure = e.what();
                          }
                          if (estop) estop_pending_ = false;
                          std::lock_guard lock(mutex_);
                          last_ = std::string("last command: ") + ground::to_string(kind) + "\n" + text;
                          if (estop) estop_unsure_ = unsure;
                          ++reports_;
                          *done = true;
                        }),
                        done});
  }
  std::pair<std::string, int> last() const {
    std::lock_guard lock(mutex_);
    return {last_, reports_};
  }
  bool estop_pending() const { return estop_pending_.load(); }
  // Waits for every command in flight (the server ends all but estops at shutdown).
  void finish() { workers_.clear(); }
  // Why the latest estop may not have landed everywhere; empty when all acked.
  std::string estop_unsure() const {
    std::lock_guard lock(mutex_);
    return estop_unsure_;
  }

 private:
  struct Worker {
    std::jthread thread;
    std::shared_ptr<std::atomic<bool>> done;
  };
  ground::OperatorServer& server_;
  std::atomic<bool> estop_pending_{false};
  mutable std::mutex mutex_;
  std::string last_;
  std::string estop_unsure_;
  int reports_ = 0;
  std::vector<Worker> workers_;  // touched by the key loop only
};

// A terminal's live table, redrawn as `status` draws it.
void show(const ground::Station& station, std::uint16_t expected, const std::string& header, const std::string& last) {
  const std::int64_t now = ground::Station::now_ns();
  std::fputs("\033[H\033[2J", stdout);
  std::fputs(header.c_str(), stdout);
  std::fputs(ground::format_status_table(station.snapshot(), now, expected).c_str(), stdout);
  std::fputs(last.c_str(), stdout);
  std::fflush(stdout);
}

void run_console(const ConsoleArgs& args) {
  const std::uint16_t expected = parse_endcap_set(args.ground.endcaps);
  const ground::StationOptions station_opts = station_options(args.ground);
  const std::filesystem::path socket =
      args.socket.empty() ? ground::default_console_socket(station_opts.domain) : std::filesystem::path(args.socket);
  ground::StationKeeper::Options keep;
  keep.expected = expected;
  ground::StationKeeper keeper([station_opts] { return std::make_unique<ground::Station>(station_opts); }, keep);
  std::unique_ptr<ground::OperatorServer> server;
  try {
    server = std::make_unique<ground::OperatorServer>([&keeper] { return keeper.current(); }, socket);
  } catch (const ground::OperatorLinkError& e) {
    throw CommandError(ExitCode::failure, std::string("console: ") + e.what());
  }
  const std::string security = station_opts.enclave_dir.empty() ? "UNSECURED" : "secured";
  std::fprintf(stderr, "console: domain %d (%s), relaying estop/stop/clear-fault at %s\n", station_opts.domain,
               security.c_str(), socket.c_str());
  const std::string header = "console, domain " + std::to_string(station_opts.domain) + " (" + security +
                             "); keys: e or space = EMERGENCY STOP, s = stop, c = clear fault, q = quit\n";
  StopOnSignals signals;
  ConsoleKeys keys;
  KeyCommands commands(*server);
  // The keeper on its own thread: making a participant must not hold up the keys.
  std::jthread keeping([&keeper](const std::stop_token& stop) {
    while (!stop.stop_requested()) {
      keeper.tick(ground::Station::now_ns());
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
  });
  int shown_reports = 0;
  std::uint16_t shown_linked = 0xFFFF;
  std::uint16_t shown_deaf = 0;
  auto next_draw = std::chrono::steady_clock::now();
  while (!signals.token().stop_requested()) {
    const ConsoleKey key = keys.next(std::chrono::milliseconds(50));
    if (key == ConsoleKey::quit) break;
    if (key == ConsoleKey::estop) commands.send(ground::CommandKind::emergency_stop, expected, args.ground.timeout_s);
    if (key == ConsoleKey::stop) commands.send(ground::CommandKind::stop, expected, args.ground.timeout_s);
    if (key == ConsoleKey::clear_fault)
      commands.send(ground::CommandKind::clear_fault, expected, args.ground.timeout_s);
    const std::int64_t now = ground::Station::now_ns();
    const auto [last, reports] = commands.last();
    if (keys.terminal()) {
      if (std::chrono::steady_clock::now() < next_draw && reports == shown_reports) continue;
      next_draw = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                         std::chrono::duration<double>(args.period_s));
      show(*keeper.current(), expected, header, last);
      shown_reports = reports;
      continue;
    }
    // Not a terminal (a log, a test): a line when the linked set changes, and each report.
    // Linked is heard and reached: an end cap heard whose readers ours have not matched
    // would not get an estop, and is named as such.
    const std::shared_ptr<ground::Station> station = keeper.current();
    const std::uint16_t linked = ground::StationKeeper::linked(*station, expected, now, keep.fresh_s);
    const auto deaf = static_cast<std::uint16_t>(station->heard(now, keep.fresh_s) & expected & ~linked);
    if (linked != shown_linked || deaf != shown_deaf) {
      std::printf("console: hears %d of %d end caps (mask 0x%03x)", std::popcount(linked), std::popcount(expected),
                  linked);
      if (deaf != 0) std::printf("; heard but not reached, an estop would not land yet: mask 0x%03x", deaf);
      std::printf("\n");
      shown_linked = linked;
      shown_deaf = deaf;
    }
    if (reports != shown_reports) std::printf("%s", last.c_str());
    shown_reports = reports;
    std::fflush(stdout);
  }
  // A stop or clear in flight ends now; an emergency stop runs to its end first, and
  // its report is the console's last word (quitting must never drop a stop).
  server->shutdown();
  if (commands.estop_pending()) std::fprintf(stderr, "console: quitting once the emergency stop in flight is done\n");
  commands.finish();
  const auto [last, reports] = commands.last();
  if (reports != shown_reports) std::printf("%s", last.c_str());
  std::fflush(stdout);
  if (const std::string unsure = commands.estop_unsure(); !unsure.empty()) {
    throw CommandError(ExitCode::failure,
                       "console: the last emergency stop did not reach every end cap (" + unsure + ")");
  }
}

}  // namespace

void add_console_command(CLI::App& app) {
  auto args = std::make_shared<ConsoleArgs>();
  CLI::App* cmd = app.add_subcommand(
      "console",
      "Operator station: join the domain once, show the end caps, emergency stop on a key (e or space); relays "
      "estop/stop/clear-fault of the ground tools on this machine so that they land in milliseconds");
  add_ground_options(*cmd, args->ground, 30.0);
  cmd->add_option("--socket", args->socket,
                  "Local socket the ground tools send through (default: $XDG_RUNTIME_DIR/tensegrity/"
                  "console-DOMAIN.sock, else /tmp/tensegrity-UID/console-DOMAIN.sock)");
  cmd->add_option("--period", args->period_s, "Refresh period of the table in seconds")->check(CLI::Range(0.05, 60.0));
  cmd->callback([args] { run_console(*args); });
}

}  // namespace tensegrity::cli
