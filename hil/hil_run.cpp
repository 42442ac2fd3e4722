// SPDX-License-Identifier: Apache-2.0
#include "hil/hil_run.hpp"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <memory>
#include <sstream>
#include <thread>

#include "hil/hil_error.hpp"
#include "hil/process_launcher.hpp"
#include "hil/provisioner.hpp"
#include "hil/realtime_priority.hpp"
#include "hil/start_handshake.hpp"
#ifdef TENSEGRITY_HIL_DDS
#include "hil/dds_provisioner.hpp"
#endif
#include "sim/episode.hpp"
#include "sim/policy.hpp"

namespace tensegrity::hil {

namespace {

template <typename T>
T stat_or(const nlohmann::json& j, const char* key, T fallback) {
  if (!j.is_object() || !j.contains(key)) return fallback;
  try {
    return j.at(key).get<T>();
  } catch (const std::exception&) {
    return fallback;
  }
}

int count_lines(const std::string& text, const std::string& needle) {
  int n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + needle.size())) ++n;
  return n;
}

// The table phase of every end cap still playing, from its --stats-json "table":
// lockstep, the table time at the last SYNC (the same SYNC for all); real time,
// the CLOCK_MONOTONIC instant of table time 0. Offsets are taken modulo the period
// against the median, so one end cap out of phase shows as that one.
void phase_offsets(std::vector<EndcapSummary>& endcaps, const std::vector<EndcapProcessReport>& reports,
                   StepperMode mode, HilResult& result) {
  std::vector<std::pair<std::size_t, double>> marks;  // (index, seconds)
  double period_s = 0.0;
  for (std::size_t i = 0; i < reports.size(); ++i) {
    const nlohmann::json& stats = reports[i].stats;
    if (!stats.is_object() || !stats.contains("table") || !stats["table"].is_object()) continue;
    const nlohmann::json& t = stats["table"];
    try {
      period_s = t.at("period_s").get<double>();
      double mark = 0.0;
      if (mode == StepperMode::lockstep) {
        mark = static_cast<double>(t.at("table_time_ns").get<std::int64_t>()) * 1e-9;
      } else {
        mark = static_cast<double>(t.at("loop_clock_origin_ns").get<std::int64_t>() +
                                   t.at("origin_loop_ns").get<std::int64_t>()) * 1e-9;
      }
      marks.emplace_back(i, mark);
    } catch (const std::exception&) {
      continue;  // an end cap from another build: no phase
    }
  }
  if (marks.empty() || !(period_s > 0.0)) return;
  const auto wrap = [period_s](double d) { return d - period_s * std::round(d / period_s); };
  std::vector<double> rel;
  for (const auto& [i, m] : marks) rel.push_back(wrap(m - marks[0].second));
  std::vector<double> sorted = rel;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  const double median = sorted[sorted.size() / 2];
  for (std::size_t k = 0; k < marks.size(); ++k) {
    EndcapSummary& s = endcaps[marks[k].first];
    s.playing = true;
    s.phase_offset_s = wrap(rel[k] - median);
    result.max_phase_offset_s = std::max(result.max_phase_offset_s, std::abs(s.phase_offset_s));
    ++result.playing;
  }
}

std::unique_ptr<Provisioner> make_provisioner(const HilOptions& options, const sim::Robot& robot,
                                              const sim::Policy& policy) {
  if (options.provision == Provision::local) return std::make_unique<LocalProvisioner>(options.policy);
#ifdef TENSEGRITY_HIL_DDS
  DdsProvisionerConfig c;
  c.domain = options.dds_domain;
  c.host_loss = options.host_loss;
  c.mode = options.mode;
  c.discovery_timeout_s = options.dds_discovery_timeout_s;
  return std::make_unique<DdsProvisioner>(robot, policy, options.policy, c);
#else
  (void)robot;
  (void)policy;
  throw HilError("this build has no DDS link (TENSEGRITY_WITH_DDS=OFF): use the local provisioner");
#endif
}

// Physics step 0 with a provisioner that talks to the running end caps: the gate
// opens, the stepper holds them while the provisioner's thread uploads and starts.
void start_with_hold(WorldStepper& stepper, Provisioner& provisioner, double timeout_s) {
  stepper.start();
  StartHandshake handshake;
  std::thread worker([&provisioner, &handshake] {
    try {
      provisioner.deliver(handshake);
    } catch (const std::exception& e) {
      handshake.fail(e.what());
    }
  });
  try {
    stepper.hold(handshake, static_cast<std::int64_t>(timeout_s * 1e9));
  } catch (...) {
    handshake.fail("the world stepper stopped holding");  // ends a wait for the freeze
    worker.join();
    throw;
  }
  worker.join();
}

}  // namespace

const char* to_string(Provision provision) { return provision == Provision::dds ? "dds" : "local"; }

Provision default_provision() {
#ifdef TENSEGRITY_HIL_DDS
  return Provision::dds;
#else
  return Provision::local;
#endif
}

HilResult run_hil(const HilOptions& options) {
  HilResult result;
  result.mode = options.mode;
  result.duration_s = options.duration_s;
  const std::int64_t t0 = monotonic_ns();
  // Declared before the launcher: the host's DDS participant outlives the end caps,
  // so they never see their host vanish before they are told to stop.
  std::unique_ptr<sim::Robot> robot_ptr;
  std::unique_ptr<sim::Policy> policy_ptr;
  std::unique_ptr<Provisioner> provisioner_ptr;
  std::unique_ptr<ProcessLauncher> launcher;
  std::unique_ptr<UdpHub> hub;
  std::unique_ptr<WorldStepper> stepper;
  bool running = false;
  try {
    robot_ptr = std::make_unique<sim::Robot>(
        sim::load_robot(!options.robot.empty() ? options.robot
                        : options.policy.empty() ? sim::default_robot_path()
                                                 : sim::robot_path_for_policy(options.policy)));
    const sim::Robot& robot = *robot_ptr;
    if (options.policy.empty()) throw HilError("no policy file (--policy)");
    policy_ptr = std::make_unique<sim::Policy>(sim::load_policy(options.policy, robot));  // fail early, with the field
    const sim::Policy& policy = *policy_ptr;
    // Before the launch and the priority raise: a DDS participant's threads take
    // the creating thread's scheduling class.
    provisioner_ptr = make_provisioner(options, robot, policy);
    Provisioner& provisioner = *provisioner_ptr;
    result.provisioner = provisioner.name();

    hub = std::make_unique<UdpHub>(robot.endcap_count());
    LauncherConfig lc;
    lc.endcap_binary = options.endcap_binary.empty() ? default_endcap_binary() : options.endcap_binary;
    lc.endcap_count = robot.endcap_count();
    for (int e = 0; e < robot.endcap_count(); ++e) lc.motors_per_endcap.push_back(static_cast<int>(robot.cables_of(e).size()));
    lc.hub_port = hub->port();
    lc.mode = options.mode;
    // The end cap's default spool: 446464 counts/rev on a 10 mm radius, 7.1e6
    // counts per metre, 0.14 um per count: about 1/1400 of one tick's motor
    // travel at 0.2 m/s, so the counts quantisation is negligible.
    lc.spool = fw::SpoolGeometry{0.01, 4096.0 * 109.0, robot.initial_rest_length_m};
    lc.limits = robot.motor;
    lc.keep_dir = options.keep_dir;
    lc.never_start = options.never_start;
    lc.extra_args = options.endcap_extra_args;
    launcher = std::make_unique<ProcessLauncher>(lc, provisioner);
    for (int e = 0; e < robot.endcap_count(); ++e) hub->set_endcap_port(e, launcher->endcap_port(e));

    StepperConfig sc;
    sc.mode = options.mode;
    sc.spool = lc.spool;
    sc.barrier_timeout_ns = static_cast<std::int64_t>(options.barrier_timeout_s * 1e9);
    sc.boot_timeout_ns = static_cast<std::int64_t>(options.boot_timeout_s * 1e9);
    sc.first_answer_timeout_ns = std::max<std::int64_t>(sc.barrier_timeout_ns, 10'000'000'000);
    sc.phase_period_steps = static_cast<std::int64_t>(std::llround(policy.period_s / robot.time_step_s));
    sc.realtime_gate_on_arrival = provisioner.needs_hold();
    stepper = std::make_unique<WorldStepper>(robot, sim::settled_state(robot, robot.time_step_s), *hub, *launcher, sc);
    stepper->set_scenario(options.scenario);
    std::unique_ptr<Recorder> recorder;
    if (!options.record_csv.empty()) {
      recorder = std::make_unique<Recorder>(options.record_csv, stepper->model());
      stepper->set_recorder(recorder.get());
    }
    if (options.after_step) {
      ProcessLauncher* l = launcher.get();
      stepper->set_step_hook([&options, l](const WorldStepper& s) { options.after_step(s, *l); });
    }

    launcher->start_all();
    const ScopedRealtimePriority priority;
    result.emulator_realtime_priority = priority.active();
    if (options.after_launch) options.after_launch(*launcher);
    stepper->boot();
    if (provisioner.needs_hold()) {
      start_with_hold(*stepper, provisioner, options.hold_timeout_s);
    } else {
      provisioner.provision(*launcher);
      provisioner.start(*launcher);
      stepper->start();
    }
    provisioner.begin_run();
    running = true;
    stepper->run(options.duration_s);
    // Real time: the end caps' own clocks keep running; serve them while they stop
    // (first thing: a sample 20 ms late is a fault), then the provisioner's threads.
    launcher->terminate_all();
    stepper->serve_until([&launcher] { return launcher->all_exited(); }, 10'000'000'000);
    provisioner.end_run();
    if (recorder) recorder->close();
    result.ok = true;
  } catch (const std::exception& e) {
    result.error = e.what();
  }
  if (provisioner_ptr) {
    if (running) provisioner_ptr->end_run();
    for (const auto& line : provisioner_ptr->log()) result.log.push_back(line);
  }
  if (stepper) {
    result.distance_m = stepper->distance_m();
    result.stats = stepper->stats();
    for (const auto& line : stepper->log()) result.log.push_back(line);
  }
  if (launcher) {
    const auto reports = launcher->shutdown();
    for (const auto& r : reports) {
      EndcapSummary s;
      s.endcap = r.endcap;
      s.exit_status = r.exit_status;
      s.cpu_s = r.cpu_s;
      s.restarts = r.restarts;
      s.cycles = stat_or<std::uint64_t>(r.stats, "cycles", 0);
      s.overruns = stat_or<std::uint64_t>(r.stats, "overruns", 0);
      s.rx_drops = stat_or<std::uint64_t>(r.stats, "rx_drops", 0);
      s.syncs = stat_or<std::uint64_t>(r.stats, "syncs_received", 0);
      s.send_failures = stat_or<std::uint64_t>(r.stats, "send_failures", 0);
      s.fault = stat_or<std::string>(r.stats, "fault", "unknown (no stats)");
      s.bring_up = stat_or<std::string>(r.stats, "bring_up", "");
      if (hub) s.bus = hub->counters(r.endcap);
      if (stepper) s.devices = stepper->devices(r.endcap).summary();
      const std::string log = launcher->log_text(r.endcap);
      s.host_losses = count_lines(log, "host LOST");
      s.host_returns = count_lines(log, "host back");
      s.link_cuts = count_lines(log, "DDS link CUT");
      s.loop_stalls = count_lines(log, "control loop STALLED");
      result.endcaps.push_back(s);
    }
    phase_offsets(result.endcaps, reports, options.mode, result);
  }
  if (hub) result.hub_syscalls = hub->syscalls();
  result.wall_s = static_cast<double>(monotonic_ns() - t0) * 1e-9;
  return result;
}

nlohmann::json to_json(const HilResult& r) {
  nlohmann::json endcaps = nlohmann::json::array();
  for (const auto& s : r.endcaps) {
    nlohmann::json phase = nullptr;
    if (s.playing) phase = s.phase_offset_s * 1e3;
    endcaps.push_back({{"endcap", s.endcap},
                       {"playing", s.playing},
                       {"phase_offset_ms", phase},
                       {"host_losses", s.host_losses},
                       {"host_returns", s.host_returns},
                       {"dds_link_cuts", s.link_cuts},
                       {"loop_stalls", s.loop_stalls},
                       {"exit_status", s.exit_status},
                       {"cpu_s", s.cpu_s},
                       {"restarts", s.restarts},
                       {"cycles", s.cycles},
                       {"overruns", s.overruns},
                       {"rx_drops", s.rx_drops},
                       {"syncs_received", s.syncs},
                       {"send_failures", s.send_failures},
                       {"fault", s.fault},
                       {"bring_up", s.bring_up},
                       {"frames_to_endcap", s.bus.tx_frames},
                       {"frames_from_endcap", s.bus.rx_frames},
                       {"malformed_from_endcap", s.bus.rx_malformed},
                       {"injected_drops", s.bus.injected_drops},
                       {"injected_corrupt", s.bus.injected_corrupt},
                       {"emcy_sent", s.devices.emcy_sent},
                       {"drive_states", s.devices.drive_states}});
  }
  const double sim_s = r.stats.sim_time_s();
  return {{"ok", r.ok},
          {"error", r.error},
          {"mode", to_string(r.mode)},
          {"distance_m", r.distance_m},
          {"sim_time_s", sim_s},
          {"run_wall_s", r.stats.run_wall_s},
          {"boot_wall_s", r.stats.boot_wall_s},
          {"speed_up", r.stats.run_wall_s > 0 ? sim_s / r.stats.run_wall_s : 0.0},
          {"steps", r.stats.steps},
          {"boot_ticks", r.stats.boot_ticks},
          {"late_steps", r.stats.late_steps},
          {"late_rate", r.stats.steps > 0 ? static_cast<double>(r.stats.late_steps) / static_cast<double>(r.stats.steps) : 0.0},
          {"max_lateness_s", r.stats.max_lateness_s},
          {"max_barrier_wait_s", r.stats.max_barrier_wait_s},
          {"send_wall_s", r.stats.send_wall_s},
          {"barrier_wall_s", r.stats.barrier_wall_s},
          {"physics_wall_s", r.stats.physics_wall_s},
          {"rejoins", r.stats.rejoins},
          {"max_tension_n", r.stats.max_tension_n},
          {"provisioner", r.provisioner},
          {"hold_ticks", r.stats.hold_ticks},
          {"hold_wall_s", r.stats.hold_wall_s},
          {"endcaps_playing", r.playing},
          {"max_phase_offset_ms", r.max_phase_offset_s * 1e3},
          {"emulator_realtime_priority", r.emulator_realtime_priority},
          {"hub_syscalls", r.hub_syscalls},
          {"log", r.log},
          {"endcaps", endcaps},
          {"wall_s", r.wall_s}};
}

std::string summary_text(const HilResult& r) {
  std::ostringstream s;
  char line[512];
  std::snprintf(line, sizeof line, "HIL %s: %s, distance %.3f m in %.1f s simulated (%.2f s wall, %.1fx real time)\n",
                to_string(r.mode), r.ok ? "ok" : "FAILED", r.distance_m, r.stats.sim_time_s(), r.stats.run_wall_s,
                r.stats.run_wall_s > 0 ? r.stats.sim_time_s() / r.stats.run_wall_s : 0.0);
  s << line;
  if (!r.ok) s << "reason: " << r.error << "\n";
  std::snprintf(line, sizeof line, "provisioner %s; %d end caps playing at the end, table phases within %.3f ms\n",
                r.provisioner.c_str(), r.playing, r.max_phase_offset_s * 1e3);
  s << line;
  if (r.mode == StepperMode::realtime) {
    std::snprintf(line, sizeof line, "late steps %lld of %lld (%.4f%%), worst %.3f ms late\n",
                  static_cast<long long>(r.stats.late_steps), static_cast<long long>(r.stats.steps),
                  r.stats.steps ? 100.0 * static_cast<double>(r.stats.late_steps) / static_cast<double>(r.stats.steps) : 0.0,
                  r.stats.max_lateness_s * 1e3);
    s << line;
  }
  for (const auto& l : r.log) s << "  " << l << "\n";
  s << "end cap  fault                 phase_ms  host lost/back  overruns  rx_drops  frames in/out  injected drop/corrupt  EMCY  cpu_s  drives\n";
  for (const auto& e : r.endcaps) {
    std::string drives;
    for (const auto& d : e.devices.drive_states) drives += (drives.empty() ? "" : ", ") + d;
    char phase[32];
    if (e.playing) {
      std::snprintf(phase, sizeof phase, "%+8.3f", e.phase_offset_s * 1e3);
    } else {
      std::snprintf(phase, sizeof phase, "%8s", "-");
    }
    std::snprintf(line, sizeof line, "%7d  %-20s  %s  %9d/%-4d  %8llu  %8llu  %6llu/%-6llu  %8llu/%-8llu  %9llu  %5.2f  %s%s\n",
                  e.endcap, e.fault.c_str(), phase, e.host_losses, e.host_returns,
                  static_cast<unsigned long long>(e.overruns), static_cast<unsigned long long>(e.rx_drops),
                  static_cast<unsigned long long>(e.bus.rx_frames), static_cast<unsigned long long>(e.bus.tx_frames),
                  static_cast<unsigned long long>(e.bus.injected_drops),
                  static_cast<unsigned long long>(e.bus.injected_corrupt),
                  static_cast<unsigned long long>(e.devices.emcy_sent), e.cpu_s, drives.c_str(),
                  e.restarts ? (" (restarted " + std::to_string(e.restarts) + "x)").c_str() : "");
    s << line;
  }
  return s.str();
}

}  // namespace tensegrity::hil
