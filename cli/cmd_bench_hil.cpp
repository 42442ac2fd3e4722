// SPDX-License-Identifier: Apache-2.0
// `tensegrity bench hil`: the HIL's performance targets (docs/design/hil-performance.md). Lockstep with
// twelve end-cap programs at 1 kHz at least 5x faster than real time; real time
// holding 1 kHz with fewer than 0.1% late steps; the CPU each end cap costs.
//
// The machine is shared, so beside the wall-clock ratio the bench reports what
// load does not change: CPU seconds of the emulator and the twelve end caps per
// simulated second over the run phase, and the speed-up that implies on idle CPUs
// (all of them busy with the HIL and nothing else: an upper bound).
#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>
#include <stop_token>
#include <thread>
#include <unistd.h>

#include "cli/commands.hpp"
#include "cli/run_cpu.hpp"
#include "cli/shipped_policy.hpp"
#include "cli/stop_signals.hpp"
#ifdef TENSEGRITY_CLI_DDS
#include "cli/ground_cli.hpp"
#include "msgs/security.hpp"
#endif
#include "hil/hil_error.hpp"
#include "hil/hil_run.hpp"
#include "hil/process_launcher.hpp"
#include "hil/timer_probe.hpp"
#include "sim/model/core_controller.hpp"
#include "sim/model/episode.hpp"
#include "robot/policy.hpp"

namespace tensegrity::cli {
namespace {

constexpr double kTargetSpeedUp = 5.0;
constexpr double kTargetLateRate = 0.001;

struct BenchHilArgs {
  std::string policy;
  double lockstep_s = 60.0;  // as long as the main job's run
  double realtime_s = 60.0;  // 60,000 steps: a 0.1 % target is 60 late steps, not 10
  double probe_s = 10.0;
  std::string endcap;
  std::string provision = hil::to_string(hil::default_provision());
  std::string keystore;
  bool insecure = false;
  bool secure = false;
  bool json = false;
};

// Samples CPU at physics step 1 and at the last step, from the stepper's step
// hook. The end caps' /proc files are read on a helper thread at the start, so a
// real-time run's step is not delayed by it; at the end the run is over.
class RunSampler {
 public:
  explicit RunSampler(std::int64_t last_step) : last_step_(last_step) {}
  ~RunSampler() {
    started_.store(2);
    started_.notify_one();
    if (reader_.joinable()) reader_.join();
  }
  void attach(hil::HilOptions& o) {
    o.after_launch = [this](hil::ProcessLauncher& l) {
      launcher_ = &l;
      reader_ = std::thread([this] {
        started_.wait(0);
        if (started_.load() == 1) start_.endcap_ns = read_endcaps();
      });
    };
    o.after_step = [this](const hil::WorldStepper& s, hil::ProcessLauncher&) {
      if (s.step_index() == kFirstStep) {
        start_ = sample_self();
        started_.store(1);
        started_.notify_one();
      } else if (s.step_index() == last_step_) {
        end_ = sample_self();
        if (reader_.joinable()) reader_.join();
        end_.endcap_ns = read_endcaps();
        complete_ = true;
      }
    };
  }
  bool complete() const { return complete_; }
  double sim_s(double dt_s) const { return static_cast<double>(last_step_ - kFirstStep) * dt_s; }
  nlohmann::json report(double dt_s) const;

 private:
  static constexpr std::int64_t kFirstStep = 1;
  std::vector<std::int64_t> read_endcaps() const {
    std::vector<std::int64_t> ns;
    for (int e = 0; e < launcher_->endcap_count(); ++e) ns.push_back(process_cpu_ns(launcher_->pid(e)));
    return ns;
  }
  std::int64_t last_step_;
  hil::ProcessLauncher* launcher_ = nullptr;
  std::thread reader_;
  std::atomic<int> started_{0};
  CpuSample start_, end_;
  bool complete_ = false;
};

double s_of(std::int64_t ns) { return static_cast<double>(ns) * 1e-9; }

nlohmann::json RunSampler::report(double dt_s) const {
  const double sim = sim_s(dt_s);
  const double wall = s_of(end_.wall_ns - start_.wall_ns);
  double endcaps = 0.0, max_endcap = 0.0;
  int counted = 0;
  for (std::size_t e = 0; e < end_.endcap_ns.size() && e < start_.endcap_ns.size(); ++e) {
    if (start_.endcap_ns[e] < 0 || end_.endcap_ns[e] < start_.endcap_ns[e]) continue;  // gone or restarted
    const double c = s_of(end_.endcap_ns[e] - start_.endcap_ns[e]);
    endcaps += c;
    max_endcap = std::max(max_endcap, c);
    ++counted;
  }
  const double emulator = s_of(end_.emulator_process_ns - start_.emulator_process_ns);
  const double stepper = s_of(end_.stepper_thread_ns - start_.stepper_thread_ns);
  const double per_sim = sim > 0 ? (emulator + endcaps) / sim : 0.0;
  const long cpus = ::sysconf(_SC_NPROCESSORS_ONLN);
  const double mean_endcap = counted ? endcaps / counted : 0.0;
  const double steal_s = start_.steal_ns >= 0 && end_.steal_ns >= 0 ? s_of(end_.steal_ns - start_.steal_ns) : -1.0;
  return {{"sim_s", sim},
          {"wall_s", wall},
          {"speed_up", wall > 0 ? sim / wall : 0.0},
          {"stepper_thread_cpu_s", stepper},
          {"emulator_process_cpu_s", emulator},
          {"endcaps_cpu_s", endcaps},
          {"endcaps_counted", counted},
          {"endcap_cpu_mean_s", mean_endcap},
          {"endcap_cpu_max_s", max_endcap},
          {"endcap_core_fraction_mean", wall > 0 ? mean_endcap / wall : 0.0},
          {"endcap_core_fraction_max", wall > 0 ? max_endcap / wall : 0.0},
          {"cpu_s_per_sim_s", per_sim},
          {"emulator_cpu_s_per_sim_s", sim > 0 ? emulator / sim : 0.0},
          {"endcaps_cpu_s_per_sim_s", sim > 0 ? endcaps / sim : 0.0},
          {"cpus", cpus},
          {"implied_speed_up_idle", per_sim > 0 ? static_cast<double>(cpus) / per_sim : 0.0},
          {"load_average_start", start_.load_average_1min},
          {"load_average_end", end_.load_average_1min},
          {"steal_s", steal_s},
          {"steal_cpu_fraction",
           steal_s >= 0 && wall > 0 && cpus > 0 ? steal_s / (wall * static_cast<double>(cpus)) : -1.0}};
}

struct ModeResult {
  hil::HilResult result;
  nlohmann::json cpu;
};

ModeResult run_mode(const BenchHilArgs& args, hil::StepperMode mode, double duration_s, double dt_s,
                    std::stop_token stop) {
  hil::HilOptions o;
  o.stop = std::move(stop);
  o.policy = shipped_policy_or(args.policy);
  o.endcap_binary = args.endcap;
  o.duration_s = duration_s;
  o.mode = mode;
  o.provision = args.provision == "local" ? hil::Provision::local : hil::Provision::dds;
#ifdef TENSEGRITY_CLI_DDS
  // Secured as `tensegrity hil` runs by default; --insecure measures without.
  if (!args.insecure) {
    o.dds_keystore = args.keystore.empty() ? msgs::default_keystore() : std::filesystem::path(args.keystore);
  }
#endif
  const auto steps = static_cast<std::int64_t>(std::llround(duration_s / dt_s));
  RunSampler sampler(steps);
  sampler.attach(o);
  ModeResult m{hil::run_hil(o), nullptr};
  if (!m.result.ok)
    throw CommandError(ExitCode::failure, std::string("bench hil (") + hil::to_string(mode) + "): " + m.result.error);
  if (!sampler.complete())
    throw CommandError(ExitCode::failure, "bench hil: the run ended before its last step was sampled");
  m.cpu = sampler.report(dt_s);
  return m;
}

double late_rate(const hil::StepperStats& s) {
  return s.steps > 0 ? static_cast<double>(s.late_steps) / static_cast<double>(s.steps) : 0.0;
}

// What the host link's bring-up cost: with DDS Security every pair of the 13
// participants authenticates before discovery goes on.
nlohmann::json link_json(const hil::LinkTiming& t) {
  if (!t.dds) return nullptr;
  return {{"dds_security", t.secured}, {"discovery_s", t.discovery_s}, {"upload_s", t.upload_s}};
}

nlohmann::json lockstep_json(const ModeResult& m, double in_process_m) {
  const hil::HilResult& r = m.result;
  const double speed_up = m.cpu["speed_up"].get<double>();
  const double implied = m.cpu["implied_speed_up_idle"].get<double>();
  const double ticks = static_cast<double>(r.stats.steps + r.stats.boot_ticks);
  const double steps = r.stats.steps > 0 ? static_cast<double>(r.stats.steps) : 1.0;
  return {{"run", m.cpu},
          {"link", link_json(r.link)},
          {"emulator_sched_fifo", r.emulator_realtime_priority},
          {"speed_up", speed_up},
          {"target_speed_up", kTargetSpeedUp},
          {"ratio_to_target", speed_up / kTargetSpeedUp},
          {"implied_ratio_to_target", implied / kTargetSpeedUp},
          {"distance_m", r.distance_m},
          {"in_process_distance_m", in_process_m},
          {"distance_difference_m", r.distance_m - in_process_m},
          {"send_us_per_step", 1e6 * r.stats.send_wall_s / steps},
          {"barrier_us_per_step", 1e6 * r.stats.barrier_wall_s / steps},
          {"physics_us_per_step", 1e6 * r.stats.physics_wall_s / steps},
          {"max_barrier_wait_s", r.stats.max_barrier_wait_s},
          {"hub_syscalls_per_tick", ticks > 0 ? static_cast<double>(r.hub_syscalls) / ticks : 0.0}};
}

nlohmann::json realtime_json(const ModeResult& m) {
  const hil::HilResult& r = m.result;
  std::uint64_t overruns = 0;
  for (const auto& e : r.endcaps) overruns += e.overruns;
  const double rate = late_rate(r.stats);
  return {{"run", m.cpu},
          {"link", link_json(r.link)},
          {"emulator_sched_fifo", r.emulator_realtime_priority},
          {"steps", r.stats.steps},
          {"late_steps", r.stats.late_steps},
          {"late_rate", rate},
          {"late_definition",
           "a step the stepper began more than half a period (0.5 ms) after its absolute deadline "
           "(run start + k periods); a stall makes several steps in a row late: one episode"},
          {"late_episodes", r.stats.lateness.late_episodes},
          {"missed_steps", r.stats.lateness.missed_steps},
          {"lateness_p50_s", 1e-9 * static_cast<double>(r.stats.lateness.p50_ns)},
          {"lateness_p99_s", 1e-9 * static_cast<double>(r.stats.lateness.p99_ns)},
          {"lateness_p999_s", 1e-9 * static_cast<double>(r.stats.lateness.p999_ns)},
          {"target_late_rate", kTargetLateRate},
          {"ratio_to_target", rate / kTargetLateRate},
          {"max_lateness_s", r.stats.max_lateness_s},
          {"stalled_s", 1e-9 * static_cast<double>(r.stats.lateness.stalled_ns)},
          {"endcap_overruns", overruns},
          {"endcap_core_fraction_mean", m.cpu["endcap_core_fraction_mean"]},
          {"endcap_core_fraction_max", m.cpu["endcap_core_fraction_max"]}};
}

nlohmann::json platform_json(const hil::TimerProbeResult& p) {
  const hil::LatenessSummary& l = p.lateness;
  return {{"what",
           "a thread that only paces like the real-time stepper (same priority, sleep then spin, "
           "absolute 1 ms deadlines), before the runs: the kernel's and hypervisor's share of lateness"},
          {"sched_fifo", p.sched_fifo},
          {"steps", l.steps},
          {"late_steps", l.late_steps},
          {"late_rate", l.steps > 0 ? static_cast<double>(l.late_steps) / static_cast<double>(l.steps) : 0.0},
          {"late_episodes", l.late_episodes},
          {"stalled_s", 1e-9 * static_cast<double>(l.stalled_ns)},
          {"lateness_p99_s", 1e-9 * static_cast<double>(l.p99_ns)},
          {"max_lateness_s", 1e-9 * static_cast<double>(l.max_ns)}};
}

void print_link(const nlohmann::json& link) {
  if (link.is_null()) return;
  std::printf("            DDS link %s: 12 end caps found in %.2f s, policy uploaded in %.1f ms\n",
              link["dds_security"].get<bool>() ? "secured (DDS Security)" : "UNSECURED (--insecure)",
              link["discovery_s"].get<double>(), 1e3 * link["upload_s"].get<double>());
}

void print_cpu(const nlohmann::json& c) {
  std::printf(
      "            CPU per simulated second %.3f s (emulator %.3f, stepper thread %.3f; end caps %.3f, %.4f each)\n",
      c["cpu_s_per_sim_s"].get<double>(), c["emulator_cpu_s_per_sim_s"].get<double>(),
      c["stepper_thread_cpu_s"].get<double>() / c["sim_s"].get<double>(), c["endcaps_cpu_s_per_sim_s"].get<double>(),
      c["endcap_cpu_mean_s"].get<double>() / c["sim_s"].get<double>());
  std::printf("            load average %.2f -> %.2f over the run; steal %.2f s (hypervisor)\n",
              c["load_average_start"].get<double>(), c["load_average_end"].get<double>(), c["steal_s"].get<double>());
}

void run_bench_hil(const BenchHilArgs& args) {
  // Ctrl-C ends a run in order: the end caps are shut down, the temp dir removed.
  const StopOnSignals stop;
  const std::filesystem::path policy_path = shipped_policy_or(args.policy);
  const sim::Robot robot = sim::load_robot(sim::robot_path_for_policy(policy_path));
  const double dt_s = robot.time_step_s;
  // The in-process reference: same policy, same start, one thread.
  sim::CoreController reference(robot, sim::load_policy(policy_path, robot));
  sim::EpisodeOptions eo;
  eo.duration_s = args.lockstep_s;
  const sim::EpisodeResult ref = sim::run_episode(robot, reference, eo);

  // First, with nothing of ours running: what the kernel and hypervisor cost a 1 kHz loop.
  std::optional<hil::TimerProbeResult> probe;
  if (args.probe_s > 0) probe = hil::probe_timer_latency(args.probe_s);
  const ModeResult lock = run_mode(args, hil::StepperMode::lockstep, args.lockstep_s, dt_s, stop.token());
  const ModeResult real = run_mode(args, hil::StepperMode::realtime, args.realtime_s, dt_s, stop.token());
  const nlohmann::json j = {{"benchmark", "hil"},
                            {"policy", policy_path.string()},
                            {"provision", args.provision},
                            {"lockstep", lockstep_json(lock, ref.distance_m)},
                            {"realtime", realtime_json(real)},
                            {"platform", probe ? platform_json(*probe) : nlohmann::json(nullptr)}};
  if (args.json) {
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  const auto& l = j["lockstep"];
  const auto& lc = l["run"];
  std::printf("bench hil: 12 endcap processes, policy %s, provision %s, %ld CPUs, emulator %s\n",
              j["policy"].get<std::string>().c_str(), args.provision.c_str(), lc["cpus"].get<long>(),
              l["emulator_sched_fifo"].get<bool>() ? "SCHED_FIFO" : "normal priority (no SCHED_FIFO)");
  std::printf("  lockstep  %.2f s simulated in %.3f s wall: %.2fx real time (target >= %.0fx, ratio %.2f)\n",
              lc["sim_s"].get<double>(), lc["wall_s"].get<double>(), l["speed_up"].get<double>(), kTargetSpeedUp,
              l["ratio_to_target"].get<double>());
  std::printf("            implied on %ld idle CPUs: %.2fx real time (ratio %.2f)\n", lc["cpus"].get<long>(),
              lc["implied_speed_up_idle"].get<double>(), l["implied_ratio_to_target"].get<double>());
  print_cpu(lc);
  std::printf("            per step: send %.1f us, barrier %.1f us, physics %.1f us; hub syscalls/tick %.2f\n",
              l["send_us_per_step"].get<double>(), l["barrier_us_per_step"].get<double>(),
              l["physics_us_per_step"].get<double>(), l["hub_syscalls_per_tick"].get<double>());
  std::printf("            distance %.4f m vs in-process %.4f m (difference %+.4f m)\n", l["distance_m"].get<double>(),
              l["in_process_distance_m"].get<double>(), l["distance_difference_m"].get<double>());
  print_link(l["link"]);
  const auto& r = j["realtime"];
  const auto& rc = r["run"];
  std::printf(
      "  realtime  %lld steps, %lld late (%.4f%%; target < %.1f%%, ratio %.2f), worst %.3f ms late, end-cap overruns "
      "%llu\n",
      r["steps"].get<long long>(), r["late_steps"].get<long long>(), 100.0 * r["late_rate"].get<double>(),
      100.0 * kTargetLateRate, r["ratio_to_target"].get<double>(), 1e3 * r["max_lateness_s"].get<double>(),
      r["endcap_overruns"].get<unsigned long long>());
  std::printf(
      "            %lld episode(s), stalled %.3f s in all; lateness p50 %.0f us, p99 %.0f us, p99.9 %.0f us (10 us "
      "buckets)\n",
      r["late_episodes"].get<long long>(), r["stalled_s"].get<double>(), 1e6 * r["lateness_p50_s"].get<double>(),
      1e6 * r["lateness_p99_s"].get<double>(), 1e6 * r["lateness_p999_s"].get<double>());
  std::printf("            late: %s\n", r["late_definition"].get<std::string>().c_str());
  std::printf("            end cap CPU %.2f%% of a core (mean), %.2f%% (max); emulator %.2f%% of a core\n",
              100.0 * rc["endcap_core_fraction_mean"].get<double>(),
              100.0 * rc["endcap_core_fraction_max"].get<double>(),
              100.0 * rc["emulator_process_cpu_s"].get<double>() / rc["wall_s"].get<double>());
  print_link(r["link"]);
  print_cpu(rc);
  if (const auto& p = j["platform"]; !p.is_null()) {
    std::printf(
        "  platform  a bare 1 kHz pacing thread (%s), %lld steps before the runs: %lld late (%.4f%%) in %lld "
        "episode(s), worst %.3f ms\n",
        p["sched_fifo"].get<bool>() ? "SCHED_FIFO" : "normal priority", p["steps"].get<long long>(),
        p["late_steps"].get<long long>(), 100.0 * p["late_rate"].get<double>(), p["late_episodes"].get<long long>(),
        1e3 * p["max_lateness_s"].get<double>());
  }
}

}  // namespace

void add_bench_hil_command(CLI::App& bench) {
  auto args = std::make_shared<BenchHilArgs>();
  CLI::App* cmd =
      bench.add_subcommand("hil", "HIL with 12 end caps: lockstep speed-up, real-time late steps, CPU per end cap");
  cmd->add_option("--policy", args->policy, std::string("Policy file (default: ") + kShippedPolicy + ")")
      ->check(CLI::ExistingFile);
  cmd->add_option("--lockstep-duration", args->lockstep_s, "Lockstep physics time, s")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 3600.0));
  cmd->add_option("--realtime-duration", args->realtime_s, "Real-time run, s")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 3600.0));
  cmd->add_option("--probe-duration", args->probe_s,
                  "Before the runs, a bare pacing thread for this long: the platform's late rate (0: skip)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 3600.0));
  cmd->add_option("--endcap", args->endcap, "The endcap program");
  cmd->add_option("--provision", args->provision, "dds or local (see `tensegrity hil --help`)")
      ->capture_default_str()
      ->check(CLI::IsMember({"dds", "local"}));
  cmd->add_flag("--json", args->json, "Print one JSON object");
#ifdef TENSEGRITY_CLI_DDS
  add_security_options(*cmd, args->keystore, args->insecure);
  cmd->add_flag("--secure", args->secure, "DDS Security with the default keystore (the default; made if missing)");
#endif
  cmd->callback([args] { run_bench_hil(*args); });
}

}  // namespace tensegrity::cli
