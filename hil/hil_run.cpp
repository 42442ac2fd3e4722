// SPDX-License-Identifier: Apache-2.0
#include "hil/hil_run.hpp"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <memory>
#include <sstream>
#include <thread>

#include "hil/clock.hpp"
#include "hil/hil_error.hpp"
#include "hil/process_launcher.hpp"
#include "hil/provisioner.hpp"
#include "hil/loop_rate.hpp"
#include "hil/realtime_priority.hpp"
#include "hil/start_handshake.hpp"
#ifdef TENSEGRITY_HIL_DDS
#include "hil/dds_provisioner.hpp"
#endif
#include "sim/model/episode.hpp"
#include "robot/policy.hpp"

namespace tensegrity::hil {

namespace {

// The table phase of every end cap still playing, from its --stats-json "table":
// lockstep, the table time at the last SYNC (the same SYNC for all); real time,
// the CLOCK_MONOTONIC instant of table time 0. Offsets are taken modulo the period
// against the median, so one end cap out of phase shows as that one.
void phase_offsets(std::vector<EndcapSummary>& endcaps, const std::vector<EndcapProcessReport>& reports,
                   StepperMode mode, HilResult& result) {
  std::vector<std::pair<std::size_t, double>> marks;  // (index, seconds)
  double period_s = 0.0;
  for (std::size_t i = 0; i < reports.size(); ++i) {
    const auto& stats = reports[i].stats;
    if (!stats || !stats->final || !stats->table) continue;  // not playing, or killed
    const fw::app::TablePhase& t = *stats->table;
    period_s = t.period_s;
    if (mode == StepperMode::lockstep) {
      marks.emplace_back(i, static_cast<double>(t.table_time_ns) * 1e-9);
    } else if (t.loop_clock_origin_ns) {
      marks.emplace_back(i, static_cast<double>(*t.loop_clock_origin_ns + t.origin_loop_ns) * 1e-9);
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
  c.keystore = options.dds_keystore;
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
  bool link_down = false;  // the worker's, read after join
  std::thread worker([&provisioner, &handshake, &link_down] {
    try {
      provisioner.deliver(handshake);
    } catch (const LinkDownError& e) {
      link_down = true;
      handshake.fail(e.what());
    } catch (const std::exception& e) {
      handshake.fail(e.what());
    }
  });
  try {
    stepper.hold(handshake, static_cast<std::int64_t>(timeout_s * 1e9));
  } catch (const std::exception& e) {
    handshake.fail("the world stepper stopped holding");  // ends a wait for the freeze
    worker.join();
    if (link_down) throw LinkDownError(e.what());  // the stepper's words, the provisioner's kind
    throw;
  } catch (...) {
    handshake.fail("the world stepper stopped holding");
    worker.join();  // whatever was thrown, never a joinable thread destroyed
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

namespace {

// One run's parts, declared in the order they must outlive each other: the host's
// DDS participant (in the provisioner) outlives the launcher's end caps, so they
// never see their host vanish before they are told to stop.
struct RunParts {
  std::unique_ptr<sim::Robot> robot;
  std::unique_ptr<sim::Policy> policy;
  std::unique_ptr<Provisioner> provisioner;
  std::unique_ptr<ProcessLauncher> launcher;
  std::unique_ptr<UdpHub> hub;
  MonotonicClock clock;
  std::unique_ptr<WorldStepper> stepper;
  std::unique_ptr<Recorder> recorder;
  bool running = false;
  // The devices at the run's last physics step. What they do after it belongs to
  // the shutdown: in real time the end caps' drives are served until their programs
  // exit, and a drive whose end cap took longer than its consumer heartbeat to exit
  // is in quick stop by then (seen once in CI-like runs of HilRejoin/realtime_dds).
  std::vector<EndcapDeviceSummary> devices_at_end;
};

void load_inputs(const HilOptions& options, RunParts& parts) {
  parts.robot = std::make_unique<sim::Robot>(sim::load_robot(!options.robot.empty() ? options.robot
                                                             : options.policy.empty()
                                                                 ? sim::default_robot_path()
                                                                 : sim::robot_path_for_policy(options.policy)));
  if (options.policy.empty()) throw HilError("no policy file (--policy)");
  check_scenario(options.scenario, *parts.robot);
  // Fail early, with the field.
  parts.policy = std::make_unique<sim::Policy>(sim::load_policy(options.policy, *parts.robot));
  // Before the launch and the priority raise: a DDS participant's threads take
  // the creating thread's scheduling class.
  parts.provisioner = make_provisioner(options, *parts.robot, *parts.policy);
}

LauncherConfig launcher_config(const HilOptions& options, const sim::Robot& robot, std::uint16_t hub_port) {
  LauncherConfig lc;
  lc.endcap_binary = options.endcap_binary.empty() ? default_endcap_binary() : options.endcap_binary;
  lc.endcap_count = robot.endcap_count();
  for (int e = 0; e < robot.endcap_count(); ++e)
    lc.motors_per_endcap.push_back(static_cast<int>(robot.cables_of(e).size()));
  lc.hub_port = hub_port;
  lc.mode = options.mode;
  lc.loop_period_ns = endcap_period_ns(robot);
  // The end cap's default spool: 446464 counts/rev on a 10 mm radius, 7.1e6
  // counts per metre, 0.14 um per count: about 1/1400 of one tick's motor
  // travel at 0.2 m/s, so the counts quantisation is negligible.
  lc.spool = fw::SpoolGeometry{};
  lc.spool.initial_rest_length_m = robot.initial_rest_length_m;
  lc.limits = robot.motor;
  lc.keep_dir = options.keep_dir;
  lc.never_start = options.never_start;
  lc.extra_args = options.endcap_extra_args;
  return lc;
}

StepperConfig stepper_config(const HilOptions& options, const RunParts& parts, const fw::SpoolGeometry& spool) {
  StepperConfig sc;
  sc.mode = options.mode;
  sc.spool = spool;
  sc.barrier_timeout_ns = static_cast<std::int64_t>(options.barrier_timeout_s * 1e9);
  sc.boot_timeout_ns = static_cast<std::int64_t>(options.boot_timeout_s * 1e9);
  sc.first_answer_timeout_ns = std::max<std::int64_t>(sc.barrier_timeout_ns, 10'000'000'000);
  sc.phase_period_steps = static_cast<std::int64_t>(std::llround(parts.policy->period_s / parts.robot->time_step_s));
  sc.realtime_gate_on_arrival = parts.provisioner->needs_hold();
  sc.max_speed = options.mode == StepperMode::lockstep ? options.max_speed : 0.0;
  return sc;
}

// The hub, the end caps' launcher (not started yet) and the stepper between them.
void assemble(const HilOptions& options, RunParts& parts) {
  const sim::Robot& robot = *parts.robot;
  parts.hub = std::make_unique<UdpHub>(robot.endcap_count());
  const LauncherConfig lc = launcher_config(options, robot, parts.hub->port());
  parts.launcher = std::make_unique<ProcessLauncher>(lc, *parts.provisioner);
  for (int e = 0; e < robot.endcap_count(); ++e) parts.hub->set_endcap_port(e, parts.launcher->endcap_port(e));
  parts.stepper =
      std::make_unique<WorldStepper>(robot, sim::settled_state(robot, robot.time_step_s), *parts.hub, *parts.launcher,
                                     stepper_config(options, parts, lc.spool), parts.clock, options.stop);
  parts.stepper->set_scenario(options.scenario);
  if (options.operator_command) parts.stepper->set_operator(options.operator_command);
  if (!options.record_csv.empty()) {
    parts.recorder = std::make_unique<Recorder>(options.record_csv, parts.stepper->model());
    parts.stepper->set_recorder(parts.recorder.get());
  }
  if (options.after_step) {
    ProcessLauncher* l = parts.launcher.get();
    parts.stepper->set_step_hook([&options, l](const WorldStepper& s) { options.after_step(s, *l); });
  }
}

// Launch, boot, provision and start, run, shut down: the run itself.
void run_phases(const HilOptions& options, RunParts& parts, HilResult& result) {
  ProcessLauncher& launcher = *parts.launcher;
  WorldStepper& stepper = *parts.stepper;
  Provisioner& provisioner = *parts.provisioner;
  launcher.start_all();
  const ScopedRealtimePriority priority;
  result.emulator_realtime_priority = priority.active();
  if (options.after_launch) options.after_launch(launcher);
  stepper.boot();
  if (provisioner.needs_hold()) {
    start_with_hold(stepper, provisioner, options.hold_timeout_s);
  } else {
    provisioner.provision(launcher);
    provisioner.start(launcher);
    stepper.start();
  }
  provisioner.begin_run();
  parts.running = true;
  stepper.run(options.duration_s);
  for (int e = 0; e < parts.robot->endcap_count(); ++e) parts.devices_at_end.push_back(stepper.devices(e).summary());
  // Real time: the end caps' own clocks keep running; serve them while they stop
  // (first thing: a sample 20 ms late is a fault), then the provisioner's threads.
  launcher.terminate_all();
  stepper.serve_until([&launcher] { return launcher.all_exited(); }, 10'000'000'000);
  provisioner.end_run();
  if (parts.recorder) parts.recorder->close();
}

EndcapSummary summarize(const EndcapProcessReport& r, const RunParts& parts) {
  EndcapSummary s;
  s.endcap = r.endcap;
  s.exit_status = r.exit_status;
  s.cpu_s = r.cpu_s;
  s.restarts = r.restarts;
  if (r.stats) {
    s.cycles = r.stats->cycles;
    s.overruns = r.stats->overruns;
    s.rx_drops = r.stats->rx_drops;
    s.syncs = r.stats->syncs_received;
    s.send_failures = r.stats->send_failures;
    s.fault = r.stats->fault;
    s.bring_up = r.stats->bring_up;
  } else {
    s.fault = r.stats_error.empty() ? "unknown (no stats)" : "unknown (" + r.stats_error + ")";
  }
  fw::app::LinkEvents link = r.earlier_link;
  if (r.stats) link += r.stats->link;
  s.host_losses = link.host_losses;
  s.host_returns = link.host_returns;
  s.link_cuts = link.link_cuts;
  s.loop_stalls = link.loop_stalls;
  s.dds_rejoins = link.rejoins;
  if (parts.hub) s.bus = parts.hub->counters(r.endcap);
  if (static_cast<std::size_t>(r.endcap) < parts.devices_at_end.size()) {
    s.devices = parts.devices_at_end[static_cast<std::size_t>(r.endcap)];
  } else if (parts.stepper) {
    s.devices = parts.stepper->devices(r.endcap).summary();  // the run ended early
  }
  return s;
}

// Whatever got built, also after a failure: logs, statistics, every end cap's report.
void collect(const HilOptions& options, RunParts& parts, HilResult& result) {
  if (parts.provisioner) {
    if (parts.running) parts.provisioner->end_run();
    for (const auto& line : parts.provisioner->log()) result.log.push_back(line);
    result.link = parts.provisioner->link_timing();
  }
  if (parts.stepper) {
    result.travel = parts.stepper->travel();
    result.distance_m = result.travel.distance_m;
    result.start_face = parts.stepper->start_face();
    result.stats = parts.stepper->stats();
    for (const auto& line : parts.stepper->log()) result.log.push_back(line);
  }
  if (parts.launcher) {
    const auto reports = parts.launcher->shutdown();
    const auto hearing = parts.provisioner ? parts.provisioner->host_hearing() : std::vector<HostHearing>{};
    for (const auto& r : reports) {
      result.endcaps.push_back(summarize(r, parts));
      if (static_cast<std::size_t>(r.endcap) < hearing.size())
        result.endcaps.back().host = hearing[static_cast<std::size_t>(r.endcap)];
    }
    phase_offsets(result.endcaps, reports, options.mode, result);
  }
  if (parts.hub) result.hub_syscalls = parts.hub->syscalls();
}

// One attempt: everything built, run and shut down. `link_down`: it failed because
// the DDS link did not come up before the start (LinkDownError), nothing moved.
HilResult run_once(const HilOptions& options, bool& link_down) {
  HilResult result;
  result.mode = options.mode;
  result.duration_s = options.duration_s;
  RunParts parts;
  try {
    load_inputs(options, parts);
    result.provisioner = parts.provisioner->name();
    assemble(options, parts);
    run_phases(options, parts, result);
    result.ok = true;
  } catch (const LinkDownError& e) {
    result.error = e.what();
    link_down = true;
  } catch (const std::exception& e) {
    result.error = e.what();
  }
  collect(options, parts, result);
  return result;
}

}  // namespace

HilResult run_hil(const HilOptions& options) {
  const std::int64_t t0 = monotonic_ns();
  const int attempts = std::max(1, options.link_attempts);
  HilOptions attempt_options = options;
  std::vector<std::string> earlier;  // the failed attempts' logs, then why each failed
  for (int attempt = 1;; ++attempt) {
    if (options.before_attempt) options.before_attempt(attempt, attempt_options);
    bool link_down = false;
    HilResult result = run_once(attempt_options, link_down);
    if (!link_down || attempt == attempts || options.stop.stop_requested()) {
      result.log.insert(result.log.begin(), earlier.begin(), earlier.end());
      result.link_attempts = attempt;
      result.wall_s = static_cast<double>(monotonic_ns() - t0) * 1e-9;
      return result;
    }
    earlier.insert(earlier.end(), result.log.begin(), result.log.end());
    earlier.push_back("dds: attempt " + std::to_string(attempt) + " of " + std::to_string(attempts) +
                      " failed before the start (" + result.error +
                      "); every end cap and the ground station start again");
    // Said now, not with the summary: the user would otherwise wait another attempt unaware.
    std::fprintf(stderr, "hil: %s\n", earlier.back().c_str());
  }
}

}  // namespace tensegrity::hil
