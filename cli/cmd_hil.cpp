// SPDX-License-Identifier: Apache-2.0
// `tensegrity hil`: the HIL emulator with twelve `endcap` programs (lockstep or
// real time, optional fault scenario and per-tick record), and
// `tensegrity bench hil`: its speed-up in lockstep, its late-step rate in real
// time and the CPU each end cap costs.
#include <sys/resource.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "hil/hil_error.hpp"
#include "hil/hil_run.hpp"
#include "sim/core_controller.hpp"
#include "sim/episode.hpp"
#include "sim/policy.hpp"

namespace tensegrity::cli {
namespace {

namespace fs = std::filesystem;

struct HilArgs {
  std::string robot;
  std::string policy;
  double duration_s = 60.0;
  std::string mode = "lockstep";
  std::string scenario;
  std::vector<std::string> faults;
  std::string record;
  std::string endcap;
  double barrier_timeout_s = 2.0;
  bool keep = false;
  bool json = false;
};

extern "C" void on_stop_signal(int) { hil::request_stop(); }

// Ctrl-C ends the run in order: the children are shut down, the temp dir removed.
void install_stop_handlers() {
  std::signal(SIGINT, on_stop_signal);
  std::signal(SIGTERM, on_stop_signal);
}

fs::path resolve_policy(const std::string& given) {
  if (!given.empty()) return given;
  const fs::path name = "policies/superball-t4-n5.json";
  if (fs::exists(name)) return name;
#ifdef TENSEGRITY_SOURCE_DIR
  if (fs::exists(fs::path(TENSEGRITY_SOURCE_DIR) / name)) return fs::path(TENSEGRITY_SOURCE_DIR) / name;
#endif
  throw CommandError(2, "no policy: " + name.string() + " not found; give one with --policy FILE");
}

hil::HilOptions make_options(const HilArgs& a) {
  hil::HilOptions o;
  o.robot = a.robot;
  o.policy = resolve_policy(a.policy);
  o.duration_s = a.duration_s;
  o.mode = a.mode == "realtime" ? hil::StepperMode::realtime : hil::StepperMode::lockstep;
  o.record_csv = a.record;
  o.endcap_binary = a.endcap;
  o.barrier_timeout_s = a.barrier_timeout_s;
  o.keep_dir = a.keep;
  const sim::Robot robot = a.robot.empty() ? sim::load_robot(sim::default_robot_path()) : sim::load_robot(a.robot);
  try {
    if (!a.scenario.empty()) o.scenario = hil::load_scenario(a.scenario, robot.endcap_count());
    for (const auto& f : a.faults) o.scenario.events.push_back(hil::parse_fault_option(f, robot.endcap_count()));
    hil::sort_events(o.scenario);
  } catch (const hil::HilError& e) {
    throw CommandError(2, e.what());
  }
  return o;
}

void run_hil_command(const HilArgs& args) {
  install_stop_handlers();
  const hil::HilResult r = hil::run_hil(make_options(args));
  if (args.json) {
    std::printf("%s\n", hil::to_json(r).dump(2).c_str());
  } else {
    std::printf("%s", hil::summary_text(r).c_str());
  }
  if (!r.ok) throw CommandError(1, "hil: " + r.error);
}

struct BenchHilArgs {
  std::string policy;
  double lockstep_s = 10.0;
  double realtime_s = 10.0;
  std::string endcap;
  bool json = false;
};

void run_bench_hil(const BenchHilArgs& args) {
  install_stop_handlers();
  HilArgs base;
  base.policy = args.policy;
  base.endcap = args.endcap;
  hil::HilOptions lock = make_options(base);
  lock.duration_s = args.lockstep_s;
  lock.mode = hil::StepperMode::lockstep;
  hil::HilOptions real = lock;
  real.duration_s = args.realtime_s;
  real.mode = hil::StepperMode::realtime;

  // The in-process reference: same policy, same start, one thread.
  const sim::Robot robot = sim::load_robot(sim::default_robot_path());
  const sim::Policy policy = sim::load_policy(lock.policy, robot);
  sim::CoreController reference(robot, policy);
  sim::EpisodeOptions eo;
  eo.duration_s = args.lockstep_s;
  const sim::EpisodeResult ref = sim::run_episode(robot, reference, eo);

  rusage before{};
  getrusage(RUSAGE_SELF, &before);
  const hil::HilResult l = hil::run_hil(lock);
  rusage after{};
  getrusage(RUSAGE_SELF, &after);
  if (!l.ok) throw CommandError(1, "bench hil (lockstep): " + l.error);
  const auto cpu_of = [](const rusage& u) {
    return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
  };
  const double emulator_cpu_s = cpu_of(after) - cpu_of(before);
  const hil::HilResult rt = hil::run_hil(real);
  if (!rt.ok) throw CommandError(1, "bench hil (realtime): " + rt.error);

  const double speed_up = l.stats.run_wall_s > 0 ? l.stats.sim_time_s() / l.stats.run_wall_s : 0.0;
  const double late_rate = rt.stats.steps > 0 ? static_cast<double>(rt.stats.late_steps) / static_cast<double>(rt.stats.steps) : 0.0;
  const auto cpu_stats = [](const hil::HilResult& r, double wall_s) {
    double sum = 0.0, max = 0.0;
    for (const auto& e : r.endcaps) {
      sum += e.cpu_s;
      max = std::max(max, e.cpu_s);
    }
    const double n = r.endcaps.empty() ? 1.0 : static_cast<double>(r.endcaps.size());
    return nlohmann::json{{"mean_cpu_s", sum / n}, {"max_cpu_s", max}, {"mean_cpu_fraction", wall_s > 0 ? sum / n / wall_s : 0.0}};
  };
  const double fidelity = ref.distance_m > 0 ? (l.distance_m - ref.distance_m) / ref.distance_m : 0.0;
  const nlohmann::json j = {
      {"benchmark", "hil"},
      {"policy", lock.policy.string()},
      {"lockstep",
       {{"sim_time_s", l.stats.sim_time_s()}, {"wall_s", l.stats.run_wall_s}, {"speed_up", speed_up},
        {"target_speed_up", 5.0}, {"ratio_to_target", speed_up / 5.0}, {"distance_m", l.distance_m},
        {"in_process_distance_m", ref.distance_m}, {"distance_relative_error", fidelity},
        {"max_barrier_wait_s", l.stats.max_barrier_wait_s}, {"emulator_cpu_s", emulator_cpu_s},
        {"hub_syscalls_per_step", l.stats.steps ? static_cast<double>(l.hub_syscalls) / static_cast<double>(l.stats.steps + l.stats.boot_ticks) : 0.0},
        {"endcap_cpu", cpu_stats(l, l.wall_s)}}},
      {"realtime",
       {{"steps", rt.stats.steps}, {"late_steps", rt.stats.late_steps}, {"late_rate", late_rate},
        {"target_late_rate", 0.001}, {"ratio_to_target", late_rate / 0.001}, {"max_lateness_s", rt.stats.max_lateness_s},
        {"overruns", [&] { std::uint64_t o = 0; for (const auto& e : rt.endcaps) o += e.overruns; return o; }()},
        {"endcap_cpu", cpu_stats(rt, rt.wall_s)}}},
  };
  if (args.json) {
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  const auto& lc = j["lockstep"];
  const auto& rc = j["realtime"];
  std::printf("bench hil: 12 endcap processes, policy %s\n", lock.policy.c_str());
  std::printf("  lockstep  %.1f s simulated in %.2f s wall: %.1fx real time (target 5x, ratio %.2f)\n",
              l.stats.sim_time_s(), l.stats.run_wall_s, speed_up, speed_up / 5.0);
  std::printf("            distance %.4f m vs in-process %.4f m (%+.3f%%); emulator CPU %.2f s; hub syscalls/tick %.1f\n",
              l.distance_m, ref.distance_m, 100.0 * fidelity, emulator_cpu_s, lc["hub_syscalls_per_step"].get<double>());
  std::printf("            end cap CPU mean %.2f s, max %.2f s (%.1f%% of a core each over the %.1f s run)\n",
              lc["endcap_cpu"]["mean_cpu_s"].get<double>(), lc["endcap_cpu"]["max_cpu_s"].get<double>(),
              100.0 * lc["endcap_cpu"]["mean_cpu_fraction"].get<double>(), l.wall_s);
  std::printf("  realtime  %lld steps, %lld late (%.4f%%; target < 0.1%%, ratio %.2f), worst %.3f ms late, end-cap overruns %llu\n",
              static_cast<long long>(rt.stats.steps), static_cast<long long>(rt.stats.late_steps), 100.0 * late_rate,
              late_rate / 0.001, rt.stats.max_lateness_s * 1e3, static_cast<unsigned long long>(rc["overruns"].get<std::uint64_t>()));
  std::printf("            end cap CPU mean %.2f s, max %.2f s (%.1f%% of a core each)\n", rc["endcap_cpu"]["mean_cpu_s"].get<double>(),
              rc["endcap_cpu"]["max_cpu_s"].get<double>(), 100.0 * rc["endcap_cpu"]["mean_cpu_fraction"].get<double>());
}

}  // namespace

void add_hil_command(CLI::App& app) {
  auto args = std::make_shared<HilArgs>();
  CLI::App* cmd = app.add_subcommand("hil", "Run the HIL emulator with 12 end-cap firmware processes");
  cmd->add_option("--robot", args->robot, "Robot description (default: robots/superball.json)")->check(CLI::ExistingFile);
  cmd->add_option("--policy", args->policy, "Policy file (default: policies/superball-t4-n5.json)")->check(CLI::ExistingFile);
  cmd->add_option("--duration", args->duration_s, "Physics time, seconds")->capture_default_str()->check(CLI::Range(0.001, 86400.0));
  cmd->add_option("--mode", args->mode, "lockstep (the emulator owns time) or realtime (1 kHz wall clock)")
      ->capture_default_str()->check(CLI::IsMember({"lockstep", "realtime"}));
  cmd->add_option("--scenario", args->scenario, "Fault scenario (tensegrity-hil-scenario/1 JSON)")->check(CLI::ExistingFile);
  cmd->add_option("--fault", args->faults, "One fault, ENDCAP:FAULT@TIME_S (repeatable), e.g. 3:drive_fault@2.0");
  cmd->add_option("--record", args->record, "Per-tick CSV: time, centre, rest lengths, tensions");
  cmd->add_option("--endcap", args->endcap, "The endcap program (default: the one built with this tree, or $TENSEGRITY_ENDCAP)");
  cmd->add_option("--barrier-timeout", args->barrier_timeout_s, "Lockstep: seconds to wait for an end cap's targets")
      ->capture_default_str()->check(CLI::Range(0.01, 600.0));
  cmd->add_flag("--keep", args->keep, "Keep the run directory (configs, stores, logs)");
  cmd->add_flag("--json", args->json, "Print one JSON object");
  cmd->callback([args] { run_hil_command(*args); });
}

void add_bench_hil_command(CLI::App& bench) {
  auto args = std::make_shared<BenchHilArgs>();
  CLI::App* cmd = bench.add_subcommand("hil", "HIL with 12 end caps: lockstep speed-up, real-time late steps, CPU per end cap");
  cmd->add_option("--policy", args->policy, "Policy file (default: policies/superball-t4-n5.json)")->check(CLI::ExistingFile);
  cmd->add_option("--lockstep-duration", args->lockstep_s, "Lockstep physics time, s")->capture_default_str()->check(CLI::Range(0.1, 3600.0));
  cmd->add_option("--realtime-duration", args->realtime_s, "Real-time run, s")->capture_default_str()->check(CLI::Range(0.1, 3600.0));
  cmd->add_option("--endcap", args->endcap, "The endcap program");
  cmd->add_flag("--json", args->json, "Print one JSON object");
  cmd->callback([args] { run_bench_hil(*args); });
}

}  // namespace tensegrity::cli
