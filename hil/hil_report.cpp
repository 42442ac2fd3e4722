// SPDX-License-Identifier: Apache-2.0
// A HIL run's result as JSON (`tensegrity hil --json`) and as the readable summary.
#include <cstdio>
#include <sstream>
#include <string>

#include "hil/hil_run.hpp"

namespace tensegrity::hil {

namespace {
std::string unheard_text(const HostHearing& h) {
  if (h.unheard == 0) return "";
  char text[96];
  std::snprintf(text, sizeof text, " (host: unheard %llux, %.1f s)", static_cast<unsigned long long>(h.unheard),
                h.unheard_s);
  return text;
}
}  // namespace

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
                       {"dds_rejoins", s.dds_rejoins},
                       {"host_unheard", s.host.unheard},
                       {"host_unheard_s", s.host.unheard_s},
                       {"host_longest_unheard_s", s.host.longest_unheard_s},
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
                       {"drive_states", s.devices.drive_states},
                       {"drive_period_ns", s.devices.drive_period_ns}});
  }
  const double sim_s = r.stats.sim_time_s();
  return {{"ok", r.ok},
          {"error", r.error},
          {"mode", to_string(r.mode)},
          {"distance_m", r.distance_m},
          {"displacement_m", {r.travel.world_m.x(), r.travel.world_m.y()}},
          {"displacement_start_m", {r.travel.start_m.x(), r.travel.start_m.y()}},
          {"heading_deg", r.travel.heading_deg ? nlohmann::json(*r.travel.heading_deg) : nlohmann::json(nullptr)},
          {"start_frame", {{"yaw_deg", r.travel.yaw_deg}, {"face", r.start_face}}},
          {"sim_time_s", sim_s},
          {"run_wall_s", r.stats.run_wall_s},
          {"boot_wall_s", r.stats.boot_wall_s},
          {"speed_up", r.stats.run_wall_s > 0 ? sim_s / r.stats.run_wall_s : 0.0},
          {"steps", r.stats.steps},
          {"boot_ticks", r.stats.boot_ticks},
          {"late_steps", r.stats.late_steps},
          {"late_rate",
           r.stats.steps > 0 ? static_cast<double>(r.stats.late_steps) / static_cast<double>(r.stats.steps) : 0.0},
          {"max_lateness_s", r.stats.max_lateness_s},
          {"max_barrier_wait_s", r.stats.max_barrier_wait_s},
          {"send_wall_s", r.stats.send_wall_s},
          {"barrier_wall_s", r.stats.barrier_wall_s},
          {"physics_wall_s", r.stats.physics_wall_s},
          {"rejoins", r.stats.rejoins},
          {"max_tension_n", r.stats.max_tension_n},
          {"provisioner", r.provisioner},
          {"link_attempts", r.link_attempts},
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
  if (r.travel.heading_deg) {
    std::snprintf(
        line, sizeof line,
        "heading %+.1f deg in the start frame (dx %.3f, dy %.3f m; world dx %.3f, dy %.3f m, yaw %+.1f deg)\n",
        *r.travel.heading_deg, r.travel.start_m.x(), r.travel.start_m.y(), r.travel.world_m.x(), r.travel.world_m.y(),
        r.travel.yaw_deg);
    s << line;
  }
  if (!r.ok) s << "reason: " << r.error << "\n";
  std::snprintf(line, sizeof line, "provisioner %s; %d end caps playing at the end, table phases within %.3f ms\n",
                r.provisioner.c_str(), r.playing, r.max_phase_offset_s * 1e3);
  s << line;
  if (r.link_attempts > 1)
    s << "link: " << r.link_attempts
      << " attempts (the DDS link was down before the start; every process started afresh)\n";
  if (r.mode == StepperMode::realtime) {
    std::snprintf(
        line, sizeof line, "late steps %lld of %lld (%.4f%%), worst %.3f ms late\n",
        static_cast<long long>(r.stats.late_steps), static_cast<long long>(r.stats.steps),
        r.stats.steps ? 100.0 * static_cast<double>(r.stats.late_steps) / static_cast<double>(r.stats.steps) : 0.0,
        r.stats.max_lateness_s * 1e3);
    s << line;
  }
  for (const auto& l : r.log) s << "  " << l << "\n";
  s << "end cap  fault                 phase_ms  host lost/back  overruns  rx_drops  frames in/out  injected "
       "drop/corrupt  EMCY  cpu_s  drives\n";
  for (const auto& e : r.endcaps) {
    std::string drives;
    for (const auto& d : e.devices.drive_states) drives += (drives.empty() ? "" : ", ") + d;
    char phase[32];
    if (e.playing) {
      std::snprintf(phase, sizeof phase, "%+8.3f", e.phase_offset_s * 1e3);
    } else {
      std::snprintf(phase, sizeof phase, "%8s", "-");
    }
    std::snprintf(line, sizeof line,
                  "%7d  %-20s  %s  %9llu/%-4llu  %8llu  %8llu  %6llu/%-6llu  %8llu/%-8llu  %9llu  %5.2f  %s%s\n",
                  e.endcap, e.fault.c_str(), phase, static_cast<unsigned long long>(e.host_losses),
                  static_cast<unsigned long long>(e.host_returns), static_cast<unsigned long long>(e.overruns),
                  static_cast<unsigned long long>(e.rx_drops), static_cast<unsigned long long>(e.bus.rx_frames),
                  static_cast<unsigned long long>(e.bus.tx_frames),
                  static_cast<unsigned long long>(e.bus.injected_drops),
                  static_cast<unsigned long long>(e.bus.injected_corrupt),
                  static_cast<unsigned long long>(e.devices.emcy_sent), e.cpu_s, drives.c_str(),
                  (std::string(e.restarts ? " (restarted " + std::to_string(e.restarts) + "x)" : "") +
                   (e.dds_rejoins ? " (DDS rejoins " + std::to_string(e.dds_rejoins) + ")" : "") + unheard_text(e.host))
                      .c_str());
    s << line;
  }
  return s.str();
}

}  // namespace tensegrity::hil
