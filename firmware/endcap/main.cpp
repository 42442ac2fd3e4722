// SPDX-License-Identifier: Apache-2.0
// endcap: the firmware of one SUPERball end cap. The program is the Endcap
// component's lifecycle (endcap.hpp: configure, activate, run, deactivate), its
// command line and its --stats-json. Two threads inside: the control loop (bus,
// core, drives; nothing else) and housekeeping (logging, the status line,
// shutdown), joined by the lock-free hand-overs of mailbox.hpp; the DDS node has
// its own.
#include <atomic>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "core/exit_code.hpp"
#include "firmware/endcap/endcap.hpp"
#include "firmware/endcap/endcap_log.hpp"

namespace app = tensegrity::fw::app;

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop.store(true); }

// HIL fault injection (--dds-cut-signals): SIGUSR1 cuts the DDS link, SIGUSR2
// restores it, SIGRTMIN+1 mutes the participant of the moment (a handshake stalled
// one way, which the node's rejoin clears). A lock-free atomic is all a handler may
// touch; the node logs it.
std::atomic<bool> g_link_cut{false};
extern "C" void on_link_signal(int signal) { g_link_cut.store(signal == SIGUSR1); }
std::atomic<std::uint32_t> g_dds_mutes{0};
extern "C" void on_mute_signal(int) { g_dds_mutes.fetch_add(1); }

// HIL fault injection, tests only (--hang-loop-signal): SIGRTMIN hangs the control
// loop for good (no cycle, no CAN heartbeat); the process and its DDS node live on.
std::atomic<bool> g_hang_loop{false};
extern "C" void on_hang_signal(int) { g_hang_loop.store(true); }

// The exit line, and the final --stats-json (endcap_stats.hpp): the run's timing
// and where the table stood at the last cycle, so a launcher can check that end
// caps play in phase.
void report_exit(const app::Endcap& endcap, const std::string& stats_path) {
  const app::EndcapStats s = endcap.stats();
  const app::TimingStats cycle = s.cycle.value_or(app::TimingStats{});
  const app::TimingStats wake = s.wakeup_latency.value_or(app::TimingStats{});
  app::log_line(
      "exit: cycles %llu overruns %llu late wakeups %llu; cycle p50 %.1f us p99 %.1f us max %.1f us; "
      "wake-up latency p50 %.1f us p99 %.1f us; VmRSS %ld kB",
      static_cast<unsigned long long>(s.cycles), static_cast<unsigned long long>(s.overruns),
      static_cast<unsigned long long>(s.late_wakeups), cycle.p50_us, cycle.p99_us, cycle.max_us, wake.p50_us,
      wake.p99_us, s.vm_rss_kb);
  if (!stats_path.empty() && !app::write_stats(stats_path, s)) app::log_line("could not write %s", stats_path.c_str());
}

// The node's rule (comms::validate): a wait shorter than a host's 2 s hearing window churns.
CLI::Validator rejoin_wait_validator() {
  return CLI::Validator(
      [](const std::string& text) -> std::string {
        double s = -1.0;
        try {
          s = std::stod(text);
        } catch (const std::exception&) {
        }
        return s == 0.0 || (s >= 3.0 && s <= 3600.0) ? "" : "expected 0 (never) or 3..3600 s, got " + text;
      },
      "0 or 3..3600");
}

void install_fault_hooks(bool cut_signals, bool hang_signal, app::EndcapOptions& o) {
  if (cut_signals) {
    std::signal(SIGUSR1, on_link_signal);
    std::signal(SIGUSR2, on_link_signal);
    std::signal(SIGRTMIN + 1, on_mute_signal);
    o.link_cut = &g_link_cut;
    o.dds_mute = &g_dds_mutes;
  }
  if (hang_signal) {
    std::signal(SIGRTMIN, on_hang_signal);
    o.hang_loop = &g_hang_loop;
  }
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
  cli.add_option("--stats-json", stats_path,
                 "write the run's statistics (tensegrity-endcap-stats/2) to this file: a snapshot every second, "
                 "the full report at exit");
  cli.add_option("--duration-s", o.duration_s, "exit after this many seconds (0: run until SIGINT/SIGTERM)");
  // Accepted in builds without DDS too (where they change nothing), so that
  // launchers and tests pass the same arguments to every build.
  cli.add_flag("--no-dds", o.no_dds, "run without the DDS link to the host (tables from --policy or storage)");
  cli.add_option("--host-loss", o.host_loss,
                 "when no host heartbeat came for 1 s, or none within 30 s of the start: stop (a playing end cap "
                 "holds, latched as the fault host_lost until clear-fault), or continue the open-loop gait")
      ->check(CLI::IsMember({"continue", "stop"}))
      ->capture_default_str();
  cli.add_option("--host-boot-grace-s", o.host_boot_grace_s,
                 "no host heard within this long of the start is a host loss too (an end cap started on boot); "
                 "at least the 1 s host timeout")
      ->check(CLI::Range(1.0, 3600.0))
      ->capture_default_str();
  cli.add_option("--unheard-rejoin-s", o.unheard_rejoin_s,
                 "hearing hosts that hear other end caps but not this one for this long, make a new DDS participant "
                 "(a stalled security handshake; the wait doubles while unanswered, up to 8x); 0: never")
      ->check(rejoin_wait_validator())
      ->capture_default_str();
  cli.add_option("--domain", o.domain, "DDS domain id (default: TENSEGRITY_DOMAIN or 42)")->check(CLI::Range(0, 232));
  std::string keystore;
  auto* keystore_opt = cli.add_option("--keystore", keystore,
                                      "DDS Security keystore (overrides the config's dds_keystore); this end cap uses "
                                      "its enclave enclaves/tensegrity/endcap_NN");
  cli.add_flag("--insecure", o.insecure, "DDS without security: any participant on the domain may command this end cap")
      ->excludes(keystore_opt);
  cli.add_flag(
      "--dds-cut-signals", cut_signals,
      "fault injection (HIL): SIGUSR1 cuts the DDS link (every datagram in and out dropped), SIGUSR2 restores it; "
      "SIGRTMIN+1 mutes the DDS participant of the moment (it hears, nothing it sends arrives; a rejoin clears it)");
  cli.add_flag("--hang-loop-signal", hang_signal,
               "fault injection (HIL tests only): SIGRTMIN hangs the control loop for good, the process lives on");
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return exit_status(tensegrity::parse_exit(cli.exit(e)));
  }
  install_fault_hooks(cut_signals, hang_signal, o);  // first thing: a SIGUSR1 before its handler ends the program
  o.config_path = config_path;
  o.keystore = keystore;
  o.policy_path = policy_path;
  o.stats_path = stats_path;

  app::Endcap endcap(o);
  try {
    endcap.configure();
    endcap.activate();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "endcap: %s\n", e.what());
    return exit_status(tensegrity::ExitCode::usage);  // nothing started: the config, storage or bus refused
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  endcap.run(g_stop);
  endcap.deactivate();
  report_exit(endcap, stats_path);
  return exit_status(tensegrity::ExitCode::ok);
}
