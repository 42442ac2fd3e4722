// SPDX-License-Identifier: Apache-2.0
// endcap: the firmware of one SUPERball end cap. The program is the Endcap
// component's lifecycle (endcap.hpp: configure, activate, run, deactivate), its
// command line and its --stats-json. Two threads inside: the control loop (bus,
// core, drives; nothing else) and housekeeping (logging, the status line,
// shutdown), joined by the lock-free hand-overs of mailbox.hpp; the DDS node has
// its own.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "firmware/app/endcap.hpp"
#include "firmware/app/endcap_log.hpp"

namespace app = tensegrity::fw::app;
namespace core = tensegrity::core;

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop.store(true); }

// HIL fault injection (--dds-cut-signals): SIGUSR1 cuts the DDS link, SIGUSR2
// restores it. A lock-free atomic store is all a handler may do; the node logs it.
std::atomic<bool> g_link_cut{false};
extern "C" void on_link_signal(int signal) { g_link_cut.store(signal == SIGUSR1); }

// HIL fault injection, tests only (--hang-loop-signal): SIGRTMIN hangs the control
// loop for good (no cycle, no CAN heartbeat); the process and its DDS node live on.
std::atomic<bool> g_hang_loop{false};
extern "C" void on_hang_signal(int) { g_hang_loop.store(true); }

long vm_rss_kb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

double us(std::int64_t ns) { return static_cast<double>(ns) * 1e-3; }

nlohmann::json summary_json(const app::TimingSummary& s) {
  return {{"count", s.count}, {"p50_us", us(s.p50_ns)}, {"p99_us", us(s.p99_ns)}, {"max_us", us(s.max_ns)}};
}

// The exit line and --stats-json: where the table stood at the last cycle, so a
// launcher can check that end caps play in phase (table time at the last loop
// time and, in real time, the CLOCK_MONOTONIC reading of loop time 0).
void report_exit(const app::Endcap& endcap, const std::string& stats_path) {
  const app::ControlLoop& loop = endcap.loop();
  const app::LoopStatus& s = loop.status();
  const app::TimingSummary cycle = loop.cycle_histogram().summary();
  const app::TimingSummary wake = loop.wakeup_histogram().summary();
  const long rss_kb = vm_rss_kb();
  app::log_line("exit: cycles %llu overruns %llu late wakeups %llu; cycle p50 %.1f us p99 %.1f us max %.1f us; "
                "wake-up latency p50 %.1f us p99 %.1f us; VmRSS %ld kB",
                static_cast<unsigned long long>(s.cycles), static_cast<unsigned long long>(s.overruns),
                static_cast<unsigned long long>(s.late_wakeups), us(cycle.p50_ns), us(cycle.p99_ns), us(cycle.max_ns),
                us(wake.p50_ns), us(wake.p99_ns), rss_kb);
  if (stats_path.empty()) return;
  nlohmann::json table_state = nullptr;
  const core::EndcapController& ctl = loop.controller();
  if (ctl.mode() == core::Mode::running) {
    table_state = {{"period_s", ctl.active_table().period_s},
                   {"loop_time_ns", s.time_ns},
                   {"table_time_ns", ctl.table_time_ns(s.time_ns)},
                   {"origin_loop_ns", s.time_ns - ctl.table_time_ns(s.time_ns)}};
    if (endcap.config().mode == app::LoopMode::realtime) table_state["loop_clock_origin_ns"] = loop.clock_origin_ns();
  }
  const nlohmann::json stats = {
      {"table", table_state},
      {"endcap", endcap.config().endcap_id},
      {"mode", to_string(endcap.config().mode)},
      {"rate_hz", endcap.config().loop_rate_hz},
      {"cycles", s.cycles},
      {"overruns", s.overruns},
      {"stalls", s.stalls},
      {"late_wakeups", s.late_wakeups},
      {"syncs_received", s.syncs_received},
      {"send_failures", s.send_failures},
      {"rx_drops", s.rx_drops},
      {"drain_limited_cycles", s.drain_limited_cycles},
      {"cycle", summary_json(cycle)},
      {"wakeup_latency", summary_json(wake)},
      {"fault", core::describe(ctl.fault())},
      {"bring_up", to_string(loop.master().bring_up_step())},
      {"vm_rss_kb", rss_kb},
  };
  std::ofstream out(stats_path);
  out << stats.dump(2) << "\n";
  if (!out) app::log_line("could not write %s", stats_path.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"endcap: firmware of one SUPERball end cap (CANopen drives + load cell, control core)"};
  app::EndcapOptions o;
  std::string config_path, policy_path, stats_path;
  bool cut_signals = false;
  bool hang_signal = false;
  cli.add_option("--id", o.id, "end cap id, 0..11")->required();
  cli.add_option("--config", config_path, "configuration file (tensegrity-endcap/1 JSON)")->required();
  cli.add_option("--policy", policy_path,
                 "policy file (tensegrity-policy/1); this end cap's share is validated and stored (with its "
                 "identity, file:NAME v0) and loaded");
  cli.add_flag("--start-on-boot", o.start_on_boot, "start playing the table as soon as the drives are enabled");
  cli.add_option("--stats-json", stats_path, "write loop timing and memory to this file at exit");
  cli.add_option("--duration-s", o.duration_s, "exit after this many seconds (0: run until SIGINT/SIGTERM)");
  // Accepted in builds without DDS too (where they change nothing), so that
  // launchers and tests pass the same arguments to every build.
  cli.add_flag("--no-dds", o.no_dds, "run without the DDS link to the host (tables from --policy or storage)");
  cli.add_option("--host-loss", o.host_loss, "when the host's heartbeat is lost: continue the gait, or stop")
      ->check(CLI::IsMember({"continue", "stop"}))
      ->capture_default_str();
  cli.add_option("--domain", o.domain, "DDS domain id (default: TENSEGRITY_DOMAIN or 42)")->check(CLI::Range(0, 232));
  std::string keystore;
  auto* keystore_opt = cli.add_option("--keystore", keystore,
                                      "DDS Security keystore (overrides the config's dds_keystore); this end cap uses "
                                      "its enclave enclaves/tensegrity/endcap_NN");
  cli.add_flag("--insecure", o.insecure, "DDS without security: any participant on the domain may command this end cap")
      ->excludes(keystore_opt);
  cli.add_flag("--dds-cut-signals", cut_signals,
               "fault injection (HIL): SIGUSR1 cuts the DDS link (every datagram in and out dropped), SIGUSR2 restores it");
  cli.add_flag("--hang-loop-signal", hang_signal,
               "fault injection (HIL tests only): SIGRTMIN hangs the control loop for good, the process lives on");
  CLI11_PARSE(cli, argc, argv);
  // First thing: a SIGUSR1 that arrived before the handler would end the program.
  if (cut_signals) {
    std::signal(SIGUSR1, on_link_signal);
    std::signal(SIGUSR2, on_link_signal);
    o.link_cut = &g_link_cut;
  }
  if (hang_signal) {
    std::signal(SIGRTMIN, on_hang_signal);
    o.hang_loop = &g_hang_loop;
  }
  o.config_path = config_path;
  o.keystore = keystore;
  o.policy_path = policy_path;

  app::Endcap endcap(o);
  try {
    endcap.configure();
    endcap.activate();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "endcap: %s\n", e.what());
    return 2;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  endcap.run(g_stop);
  endcap.deactivate();
  report_exit(endcap, stats_path);
  return 0;
}
