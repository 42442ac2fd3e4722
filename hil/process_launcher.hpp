// SPDX-License-Identifier: Apache-2.0
// Starts and stops the twelve `endcap` programs of a HIL run: generated configs
// in a temporary directory, a storage directory each, a free UDP port each on
// 127.0.0.1, logs to files. No orphans: every child gets PR_SET_PDEATHSIG
// (SIGKILL when the launcher dies, even by SIGKILL) and its own process group
// (so a terminal's Ctrl-C reaches only the launcher, which then shuts the
// children down in order, and a kill reaches anything a child started).
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "firmware/app/endcap_stats.hpp"
#include "core/limits.hpp"
#include "core/loop_period.hpp"
#include "firmware/drivers/spool_geometry.hpp"
#include "hil/devices/udp_ports.hpp"
#include "hil/provisioner.hpp"
#include "hil/world_stepper.hpp"

namespace tensegrity::hil {

struct LauncherConfig {
  std::filesystem::path endcap_binary;
  int endcap_count = 12;
  std::vector<int> motors_per_endcap;  // from the robot; default 2 each
  std::uint16_t hub_port = 0;
  StepperMode mode = StepperMode::lockstep;
  std::int64_t loop_period_ns = core::kDefaultLoopPeriodNs;  // the robot's time step (loop_rate.hpp)
  fw::SpoolGeometry spool;
  core::MotorLimits limits;
  bool keep_dir = false;                               // leave configs, stores and logs behind (debugging)
  std::vector<int> never_start;                        // tests: end caps whose program is not started
  std::map<int, std::vector<std::string>> extra_args;  // tests: appended to an end cap's arguments
};

struct EndcapProcessReport {
  int endcap = 0;
  bool started = false;
  int exit_status = -1;  // exit code, or -signal
  double cpu_s = 0.0;    // user + system, read from /proc/PID/stat before the stop
  std::uint64_t restarts = 0;
  // The program's --stats-json of its last incarnation (final, or the last
  // once-a-second snapshot of one that was killed); absent if none was readable.
  std::optional<fw::app::EndcapStats> stats;
  std::string stats_error;  // why not, when a file was there
  // The link's events of the incarnations before it (killed by a fault scenario).
  fw::app::LinkEvents earlier_link;
};

class ProcessLauncher final : public EndcapProcesses {
 public:
  ProcessLauncher(const LauncherConfig& config, Provisioner& provisioner);
  ~ProcessLauncher() override;
  ProcessLauncher(const ProcessLauncher&) = delete;
  ProcessLauncher& operator=(const ProcessLauncher&) = delete;

  void start_all();
  std::uint16_t endcap_port(int endcap) const { return slots_[endcap].port; }
  int endcap_count() const { return static_cast<int>(slots_.size()); }
  bool started(int endcap) const { return slots_[endcap].pid > 0; }
  pid_t pid(int endcap) const { return slots_[endcap].pid; }
  std::string log_text(int endcap) const;
  const std::filesystem::path& dir() const { return dir_; }
  // CPU seconds so far of a running end cap, from /proc/PID/stat.
  double cpu_s(int endcap) const;

  bool listening(int endcap) override;
  bool exited(int endcap) override;
  std::string describe(int endcap) override;
  void kill(int endcap) override;
  void restart(int endcap) override;
  // SIGUSR1 (cut) / SIGUSR2 (restore) to a program started with --dds-cut-signals.
  std::string set_dds_link(int endcap, bool up) override;
  std::string mute_dds(int endcap) override;
  // SIGSTOP, or SIGRTMIN to a program started with --hang-loop-signal (loop_only).
  std::string freeze(int endcap, bool loop_only) override;

  // SIGTERM to every end cap, without waiting (so the emulator can keep serving
  // their buses while they stop); idempotent.
  void terminate_all();
  // Every end cap's program has exited (reaps them).
  bool all_exited();
  // terminate_all(), wait (then SIGKILL), collect stats; idempotent.
  std::vector<EndcapProcessReport> shutdown();

 private:
  struct Slot {
    std::uint16_t port = 0;
    pid_t pid = -1;
    int exit_status = -1;
    double cpu_before_s = 0.0;  // CPU of earlier (killed) incarnations
    std::uint64_t restarts = 0;
    std::filesystem::path config, log, stats;
    std::vector<std::filesystem::path> earlier_stats;  // each restart's predecessor's
  };
  void spawn(int endcap, bool restart);
  void reap(int endcap, bool block);
  static void read_stats(const Slot& slot, EndcapProcessReport& report);

  LauncherConfig config_;
  Provisioner& provisioner_;
  std::filesystem::path dir_;
  std::vector<Slot> slots_;
  std::vector<EndcapProcessReport> reports_;
  std::vector<double> terminate_cpu_s_;  // CPU seconds when terminate_all() ran
  bool shut_down_ = false;
};

// The drives' consumer heartbeat time the launcher configures in real time (the
// end cap's default, 50 ms, in lockstep).
inline constexpr double kRealtimeConsumerHeartbeatS = 0.2;
// The end cap's own silence timeouts in real time (drive and load-cell heartbeats,
// drive positions, load-cell samples; 20-100 ms by default, kept in lockstep).
inline constexpr double kRealtimeSilenceTimeoutS = 0.2;

// The `endcap` program: $TENSEGRITY_ENDCAP, else the one built with this tree.
std::filesystem::path default_endcap_binary();

}  // namespace tensegrity::hil
