// SPDX-License-Identifier: Apache-2.0
// One whole HIL run, as `tensegrity hil` and the tests do it: the emulator's hub,
// twelve end-cap programs, boot to the start gate, provisioning (over DDS as on the
// robot, or locally), an in-phase start, the run, a clean shutdown and a summary
// with each end cap's table phase. Errors become HilResult::error (the reason),
// never a hang or an orphan process. docs/guide/hil.md.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <stop_token>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "hil/provisioner.hpp"
#include "hil/scenario.hpp"
#include "hil/world_stepper.hpp"

namespace tensegrity::hil {

class ProcessLauncher;

// How the policy reaches the end caps and how they are started (provisioner.hpp).
enum class Provision : std::uint8_t {
  dds,    // over DDS, as on the robot: upload + start command (dds_provisioner.hpp)
  local,  // --policy FILE --start-on-boot --no-dds and the stepper's start gate
};
const char* to_string(Provision provision);
// The default: dds when this build has the DDS link.
Provision default_provision();

struct HilOptions {
  std::filesystem::path robot;  // empty: the default robot
  std::filesystem::path policy;
  double duration_s = 60.0;
  StepperMode mode = StepperMode::lockstep;
  Scenario scenario;
  std::filesystem::path record_csv;     // empty: none
  std::filesystem::path endcap_binary;  // empty: default_endcap_binary()
  double barrier_timeout_s = 2.0;
  double max_speed = 0.0;  // lockstep: physics at most this many times real time (0: no limit)
  double boot_timeout_s = 30.0;
  Provision provision = default_provision();
  std::string host_loss = "stop";  // the end caps' --host-loss (dds)
  int dds_domain = -1;             // -1: a free one of the HIL's range (dds_domain.hpp)
  // dds: DDS Security keystore (created if missing); empty: unsecured (--insecure).
  std::filesystem::path dds_keystore;
  double hold_timeout_s = 60.0;  // dds: gate open to physics step 0
  bool keep_dir = false;
  // dds: every end cap on the link, clock synchronized. Secured discovery (each pair
  // of 13 participants authenticates first) took 7-22 s lockstep, 24 s real time
  // here; below hold_timeout_s, so that a missing end cap is named.
  double dds_discovery_timeout_s = 45.0;
  // dds: how many times the whole run is started afresh (every end cap and the ground
  // station new) when the link did not come up before the start. Fast DDS 2.9's
  // secured discovery now and then leaves one end cap unmatched whichever station
  // joins (docs/guide/security.md, "A stalled handshake"); new participants on both sides
  // authenticate afresh. Nothing has moved before the start, so a retry is clean.
  int link_attempts = 3;
  std::vector<int> never_start;                               // tests
  std::map<int, std::vector<std::string>> endcap_extra_args;  // tests: more arguments for an end cap
  // Tests: called once the end caps are running, before boot (e.g. to SIGSTOP one).
  std::function<void(ProcessLauncher&)> after_launch;
  std::function<void(const WorldStepper&, ProcessLauncher&)> after_step;
  // The scenario's operator commands (estop, clear_fault, start) go here, on the
  // stepper's thread: it must not block (tensegrity soak's operator queues them).
  // Unset: such an event is logged as not done.
  OperatorCommand operator_command;
  // Tests: called before each attempt (1, 2, ...) with that attempt's options.
  std::function<void(int attempt, HilOptions&)> before_attempt;
  // A stop requested here (Ctrl-C in the launcher) ends the run in order with
  // "interrupted": the end caps are shut down, the run directory removed.
  std::stop_token stop;
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
  // Table phase at the end of the run relative to the median of the end caps
  // playing (wrapped to +- half a period); absent if it was not playing. Lockstep:
  // table times at the last SYNC; real time: CLOCK_MONOTONIC instants of table time 0.
  bool playing = false;
  double phase_offset_s = 0.0;
  // From its stats (every incarnation): host losses seen, DDS link cuts (fault
  // injection), loop stalls (the DDS node withheld its heartbeat), new DDS
  // participants the end cap made because no host heard it.
  std::uint64_t host_losses = 0;
  std::uint64_t host_returns = 0;
  std::uint64_t link_cuts = 0;
  std::uint64_t loop_stalls = 0;
  std::uint64_t dds_rejoins = 0;
  // The host's side (real time, dds; provisioner.hpp's HostHearing): how often and how
  // long it went 2 s or more without this end cap's heartbeat.
  HostHearing host;
};

struct HilResult {
  bool ok = false;
  std::string error;  // why not ok
  double distance_m = 0.0;
  sim::Travel travel;           // where the robot went, world and start frame
  std::vector<int> start_face;  // the end caps it stood on at physics step 0
  double duration_s = 0.0;
  StepperMode mode = StepperMode::lockstep;
  StepperStats stats;
  std::vector<EndcapSummary> endcaps;
  std::vector<std::string> log;
  LinkTiming link;  // how the host link came up (dds)
  double wall_s = 0.0;
  std::string provisioner;
  double max_phase_offset_s = 0.0;  // over the end caps playing at the end
  int playing = 0;                  // end caps playing their table at the end
  std::uint64_t hub_syscalls = 0;
  bool emulator_realtime_priority = false;  // SCHED_FIFO above the end caps' loops
  int link_attempts = 1;                    // runs started to get this one (HilOptions::link_attempts)
};

HilResult run_hil(const HilOptions& options);
nlohmann::json to_json(const HilResult& result);
std::string summary_text(const HilResult& result);

}  // namespace tensegrity::hil
