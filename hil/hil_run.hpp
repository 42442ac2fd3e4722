// SPDX-License-Identifier: Apache-2.0
// One whole HIL run, as `tensegrity hil` and the tests do it: the emulator's hub,
// twelve end-cap programs, provisioning, boot to the start gate, an in-phase
// start, the run, a clean shutdown and a summary. Errors become
// HilResult::error (the reason), never a hang or an orphan process.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "hil/scenario.hpp"
#include "hil/world_stepper.hpp"

namespace tensegrity::hil {

class ProcessLauncher;

struct HilOptions {
  std::filesystem::path robot;  // empty: the default robot
  std::filesystem::path policy;
  double duration_s = 60.0;
  StepperMode mode = StepperMode::lockstep;
  Scenario scenario;
  std::filesystem::path record_csv;  // empty: none
  std::filesystem::path endcap_binary;  // empty: default_endcap_binary()
  double barrier_timeout_s = 2.0;
  double boot_timeout_s = 30.0;
  bool keep_dir = false;
  std::vector<int> never_start;  // tests
  // Tests: called once the end caps are running, before boot (e.g. to SIGSTOP one).
  std::function<void(ProcessLauncher&)> after_launch;
  std::function<void(const WorldStepper&, ProcessLauncher&)> after_step;
};

struct EndcapSummary {
  int endcap = 0;
  int exit_status = -1;
  double cpu_s = 0.0;
  std::uint64_t restarts = 0;
  // From the end cap's --stats-json (its last incarnation).
  std::uint64_t cycles = 0, overruns = 0, rx_drops = 0, syncs = 0, send_failures = 0;
  std::string fault = "none";
  std::string bring_up;
  // From the emulator's side of its bus.
  BusCounters bus;
  EndcapDeviceSummary devices;
};

struct HilResult {
  bool ok = false;
  std::string error;  // why not ok
  double distance_m = 0.0;
  double duration_s = 0.0;
  StepperMode mode = StepperMode::lockstep;
  StepperStats stats;
  std::vector<EndcapSummary> endcaps;
  std::vector<std::string> log;
  double wall_s = 0.0;
  std::string provisioner;
  std::uint64_t hub_syscalls = 0;
  bool emulator_realtime_priority = false;  // SCHED_FIFO above the end caps' loops
};

HilResult run_hil(const HilOptions& options);
nlohmann::json to_json(const HilResult& result);
std::string summary_text(const HilResult& result);

}  // namespace tensegrity::hil
