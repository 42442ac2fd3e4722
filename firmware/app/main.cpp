// SPDX-License-Identifier: Apache-2.0
// endcap: the firmware of one SUPERball end cap. Two threads: the control loop
// (bus, core, drives; nothing else) and housekeeping (logging, persisting tables,
// the periodic status line, shutdown), joined by the lock-free hand-overs of
// mailbox.hpp so the loop never waits on logging or storage.
#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "firmware/app/config.hpp"
#include "firmware/app/control_loop.hpp"
#include "firmware/app/host_link.hpp"
#include "firmware/app/policy_file.hpp"
#include "firmware/app/policy_store.hpp"
#include "firmware/drivers/emcy.hpp"
#include "firmware/hal/clock.hpp"
#include "firmware/hal/make_can_bus.hpp"
#include "firmware/hal/storage.hpp"
#ifdef TENSEGRITY_ENDCAP_DDS
#include "firmware/comms/endcap_node.hpp"
#include "msgs/dds.hpp"
#endif

namespace app = tensegrity::fw::app;
namespace fw = tensegrity::fw;
namespace core = tensegrity::core;
#ifdef TENSEGRITY_ENDCAP_DDS
namespace comms = tensegrity::fw::comms;
namespace msgs = tensegrity::msgs;
#endif

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
// The loop's progress, one per pass (a lockstep wait included): the DDS node's watchdog.
std::atomic<std::uint64_t> g_loop_progress{0};

int g_id = 0;
template <typename... Args>
void log_line(const char* format, Args... args) {
  char text[512];
  std::snprintf(text, sizeof text, format, args...);
  std::fprintf(stderr, "endcap %d: %s\n", g_id, text);
}
void log_text(const std::string& text) { std::fprintf(stderr, "endcap %d: %s\n", g_id, text.c_str()); }

long vm_rss_kb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

void log_event(const app::AppEvent& e) {
  const double t_s = static_cast<double>(e.time_ns) * 1e-9;
  switch (e.kind) {
    case app::AppEventKind::fault_latched:
    case app::AppEventKind::fault_cleared:
    case app::AppEventKind::start_refused:
      log_line("t=%.3f s %s: %s", t_s, to_string(e.kind), core::describe(e.cause));
      break;
    case app::AppEventKind::table_accepted:
    case app::AppEventKind::table_rejected:
      log_line("t=%.3f s %s: %s", t_s, to_string(e.kind), core::describe(e.table_error));
      break;
    case app::AppEventKind::bring_up_failed:
      log_line("t=%.3f s bring-up failed: %s (retrying)", t_s, e.text.data());
      break;
    case app::AppEventKind::master_event:
      // SDO results are bring-up chatter; bring-up outcomes are the loop's own events.
      if (e.master_kind == fw::canopen::MasterEventKind::sdo_finished ||
          e.master_kind == fw::canopen::MasterEventKind::bring_up_done ||
          e.master_kind == fw::canopen::MasterEventKind::bring_up_failed) {
        break;
      }
      if (e.master_kind == fw::canopen::MasterEventKind::emcy) {
        log_line("t=%.3f s node %u: EMCY 0x%04X (%s)", t_s, static_cast<unsigned>(e.node_id),
                 static_cast<unsigned>(e.emcy_code), fw::canopen::emcy_error_text(e.emcy_code));
      } else {
        log_line("t=%.3f s node %u: %s", t_s, static_cast<unsigned>(e.node_id), to_string(e.master_kind));
      }
      break;
    default: log_line("t=%.3f s %s", t_s, to_string(e.kind)); break;
  }
}

double us(std::int64_t ns) { return static_cast<double>(ns) * 1e-3; }

nlohmann::json summary_json(const app::TimingSummary& s) {
  return {{"count", s.count}, {"p50_us", us(s.p50_ns)}, {"p99_us", us(s.p99_ns)}, {"max_us", us(s.max_ns)}};
}

// Real-time priority when allowed (root or CAP_SYS_NICE, as the systemd unit
// grants); otherwise the loop runs at normal priority and says so.
void try_realtime_priority(std::thread& thread) {
  sched_param param{};
  param.sched_priority = 80;
  const int rc = pthread_setschedparam(thread.native_handle(), SCHED_FIFO, &param);
  if (rc != 0) log_line("SCHED_FIFO not available (%s): loop runs at normal priority", std::strerror(rc));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"endcap: firmware of one SUPERball end cap (CANopen drives + load cell, control core)"};
  int id = -1;
  std::string config_path;
  std::string policy_path;
  std::string stats_path;
  bool start_on_boot = false;
  double duration_s = 0.0;
  bool no_dds = false;
  std::string host_loss = "continue";
  int domain = -1;
  bool cut_signals = false;
  bool hang_signal = false;
  cli.add_option("--id", id, "end cap id, 0..11")->required();
  cli.add_option("--config", config_path, "configuration file (tensegrity-endcap/1 JSON)")->required();
  cli.add_option("--policy", policy_path,
                 "policy file (tensegrity-policy/1); this end cap's share is validated, stored and loaded");
  cli.add_flag("--start-on-boot", start_on_boot, "start playing the table as soon as the drives are enabled");
  cli.add_option("--stats-json", stats_path, "write loop timing and memory to this file at exit");
  cli.add_option("--duration-s", duration_s, "exit after this many seconds (0: run until SIGINT/SIGTERM)");
  // Accepted in builds without DDS too (where they change nothing), so that
  // launchers and tests pass the same arguments to every build.
  cli.add_flag("--no-dds", no_dds, "run without the DDS link to the host (tables from --policy or storage)");
  cli.add_option("--host-loss", host_loss, "when the host's heartbeat is lost: continue the gait, or stop")
      ->check(CLI::IsMember({"continue", "stop"}))
      ->capture_default_str();
  cli.add_option("--domain", domain, "DDS domain id (default: TENSEGRITY_DOMAIN or 42)")->check(CLI::Range(0, 232));
  cli.add_flag("--dds-cut-signals", cut_signals,
               "fault injection (HIL): SIGUSR1 cuts the DDS link (every datagram in and out dropped), SIGUSR2 restores it");
  cli.add_flag("--hang-loop-signal", hang_signal,
               "fault injection (HIL tests only): SIGRTMIN hangs the control loop for good, the process lives on");
  CLI11_PARSE(cli, argc, argv);
  g_id = id;
  // First thing: a SIGUSR1 that arrived before the handler would end the program.
  if (cut_signals) {
    std::signal(SIGUSR1, on_link_signal);
    std::signal(SIGUSR2, on_link_signal);
  }
  if (hang_signal) std::signal(SIGRTMIN, on_hang_signal);

  app::EndcapAppConfig config;
  core::EndcapTable table;
  bool have_table = false;
  std::unique_ptr<fw::FileStorage> storage;
  try {
    config = app::load_config(config_path, id);
    if (start_on_boot) config.start_on_boot = true;
    std::error_code ec;
    std::filesystem::create_directories(config.storage_dir, ec);
    if (ec) throw app::ConfigError(config_path + ": storage_dir: cannot create " + config.storage_dir.string() + ": " + ec.message());
    storage = std::make_unique<fw::FileStorage>(config.storage_dir);
    app::PolicyStore store(*storage, config.motor_count, config.limits);
    if (!policy_path.empty()) {
      table = app::load_endcap_table(policy_path, id, config.motor_count, config.limits);
      std::string error;
      if (store.save(table, error) != fw::StorageResult::ok) log_text("could not store the policy: " + error);
      have_table = true;
      log_text("policy " + policy_path + " loaded and stored");
    } else {
      app::StoredTable stored;
      std::string report;
      have_table = store.load(stored, report);
      if (!report.empty()) log_text("policy store: " + report);
      if (have_table) {
        table = stored.table;
        log_line("restored table generation %llu", static_cast<unsigned long long>(stored.generation));
      } else {
        log_text("no stored table: idle until one arrives");
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "endcap: %s\n", e.what());
    return 2;
  }

  fw::MakeCanBusResult bus = fw::make_can_bus(config.bus);
  if (!bus) {
    std::fprintf(stderr, "endcap: %s: bus: %s\n", config_path.c_str(), bus.error.c_str());
    return 2;
  }

  fw::SystemClock clock;
  app::NullHostLink null_host;
  app::HostLink* host = &null_host;
#ifdef TENSEGRITY_ENDCAP_DDS
  // The DDS node runs on its own threads and meets the loop only in mailboxes.
  std::unique_ptr<comms::EndcapNode> node;
  if (!no_dds) {
    try {
      comms::EndcapNodeConfig node_config;
      node_config.endcap_id = id;
      node_config.domain = domain >= 0 ? domain : msgs::domain_id();
      node_config.expect.motor_count = config.motor_count;
      node_config.expect.limits = config.limits;
      node_config.host_loss = comms::parse_host_loss_action(host_loss);
      if (config.mode == app::LoopMode::lockstep) {
        node_config.start_grid_ns = comms::kLockstepStartGridPeriods * config.period_ns();
      }
      if (cut_signals) node_config.link_cut = &g_link_cut;
      node_config.loop_progress = &g_loop_progress;
      node = std::make_unique<comms::EndcapNode>(node_config, clock, storage.get());
      node->start();
      host = node.get();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "endcap: DDS: %s\n", e.what());
      return 2;
    }
  }
#else
  (void)no_dds;
  (void)host_loss;
  (void)domain;
#endif
  auto loop = std::make_unique<app::ControlLoop>(*bus.bus, clock, *host, app::make_loop_settings(config));
  if (have_table && loop->load_table(table) != core::TableError::none) {
    log_text("stored table rejected by the core");  // cannot happen: validated above
  }
  log_line("bus %s, %u motor(s), %s at %.0f Hz%s", config.bus.c_str(), config.motor_count, to_string(config.mode),
           config.loop_rate_hz, config.start_on_boot ? ", start on boot" : "");

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  std::atomic<bool> loop_stop{false};
  std::thread loop_thread([&] {
    while (!loop_stop.load(std::memory_order_relaxed)) {
      if (g_hang_loop.load(std::memory_order_relaxed)) {  // the test hook: hung, until asked to exit
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        continue;
      }
      g_loop_progress.fetch_add(1, std::memory_order_relaxed);
      if (config.mode == app::LoopMode::realtime) {
        loop->run_realtime_cycle();
      } else {
        loop->run_lockstep_cycle(100'000'000);
      }
    }
  });
  try_realtime_priority(loop_thread);

  app::PolicyStore store(*storage, config.motor_count, config.limits);
  const auto started = std::chrono::steady_clock::now();
  for (;;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    app::AppEvent event;
    while (loop->pop_event(event)) log_event(event);
    core::EndcapTable to_store;
    if (loop->take_table_to_persist(to_store)) {
      std::string error;
      if (store.save(to_store, error) != fw::StorageResult::ok) log_text("could not store the table: " + error);
    }
    app::LoopStatus s;
    if (loop->read_status(s)) {
      log_line("t=%.1f s cycles %llu overruns %llu late %llu cycle p50 %.1f us p99 %.1f us max %.1f us, %s%s%s",
               static_cast<double>(s.time_ns) * 1e-9, static_cast<unsigned long long>(s.cycles),
               static_cast<unsigned long long>(s.overruns), static_cast<unsigned long long>(s.late_wakeups),
               static_cast<double>(s.cycle_window.p50_ns) / 1e3, static_cast<double>(s.cycle_window.p99_ns) / 1e3,
               static_cast<double>(s.cycle_window.max_ns) / 1e3,
               s.mode == core::Mode::running ? "running" : (s.mode == core::Mode::faulted ? "faulted" : "idle"),
               s.fault != core::FaultCause::none ? ": " : "",
               s.fault != core::FaultCause::none ? core::describe(s.fault) : "");
    }
    const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    if (g_stop.load() || (duration_s > 0.0 && elapsed_s >= duration_s)) break;
  }
  loop_stop.store(true);
  loop_thread.join();
#ifdef TENSEGRITY_ENDCAP_DDS
  if (node) node->stop();
#endif
  app::AppEvent event;
  while (loop->pop_event(event)) log_event(event);

  const app::LoopStatus& s = loop->status();
  const app::TimingSummary cycle = loop->cycle_histogram().summary();
  const app::TimingSummary wake = loop->wakeup_histogram().summary();
  const long rss_kb = vm_rss_kb();
  log_line("exit: cycles %llu overruns %llu late wakeups %llu; cycle p50 %.1f us p99 %.1f us max %.1f us; "
           "wake-up latency p50 %.1f us p99 %.1f us; VmRSS %ld kB",
           static_cast<unsigned long long>(s.cycles), static_cast<unsigned long long>(s.overruns),
           static_cast<unsigned long long>(s.late_wakeups), us(cycle.p50_ns), us(cycle.p99_ns), us(cycle.max_ns),
           us(wake.p50_ns), us(wake.p99_ns), rss_kb);
  if (!stats_path.empty()) {
    // Where the table stood at the last cycle, so a launcher can check that end caps
    // play in phase: table time at the last loop time and, in real time, the
    // CLOCK_MONOTONIC reading of loop time 0 (table time 0 = that + origin_loop_ns).
    nlohmann::json table_state = nullptr;
    const core::EndcapController& ctl = loop->controller();
    if (ctl.mode() == core::Mode::running) {
      table_state = {{"period_s", ctl.active_table().period_s},
               {"loop_time_ns", s.time_ns},
               {"table_time_ns", ctl.table_time_ns(s.time_ns)},
               {"origin_loop_ns", s.time_ns - ctl.table_time_ns(s.time_ns)}};
      if (config.mode == app::LoopMode::realtime) table_state["loop_clock_origin_ns"] = loop->clock_origin_ns();
    }
    const nlohmann::json stats = {
        {"table", table_state},
        {"endcap", id},
        {"mode", to_string(config.mode)},
        {"rate_hz", config.loop_rate_hz},
        {"cycles", s.cycles},
        {"overruns", s.overruns},
        {"late_wakeups", s.late_wakeups},
        {"syncs_received", s.syncs_received},
        {"send_failures", s.send_failures},
        {"rx_drops", s.rx_drops},
        {"cycle", summary_json(cycle)},
        {"wakeup_latency", summary_json(wake)},
        {"fault", core::describe(loop->controller().fault())},
        {"bring_up", to_string(loop->master().bring_up_step())},
        {"vm_rss_kb", rss_kb},
    };
    std::ofstream out(stats_path);
    out << stats.dump(2) << "\n";
    if (!out) log_text("could not write " + stats_path);
  }
  return 0;
}
