// SPDX-License-Identifier: Apache-2.0
// Fault-injection scenarios: what goes wrong, where and when, as a JSON file
//   {"format": "tensegrity-hil-scenario/1",
//    "events": [{"time_s": 2.0, "endcap": 3, "fault": "drive_fault", "params": {"motor": 0}}, ...]}
// or one `--fault` option per event ("3:drive_fault@2.0"). time_s is physics
// time (table time 0 is the first physics step). Parsed and validated before
// anything starts, so a typo costs nothing.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "hil/udp_hub.hpp"
#include "robot/robot.hpp"

namespace tensegrity::hil {

enum class FaultKind : std::uint8_t {
  drive_fault,      // the drive faults (EMCY); params: motor, code, release
  drive_silent,     // the drive stops answering (no heartbeat/PDO/SDO); params: motor (-1: all)
  load_cell_stuck,  // value and sequence freeze
  load_cell_drift,  // params: n_per_s
  drop_frames,      // frames to the end cap lost; params: probability, duration_s
  corrupt_frames,   // frames to the end cap corrupted; params: probability, duration_s, kind
  kill_endcap,      // SIGKILL the end cap's process
  restart_endcap,   // start it again (stored policy, start on boot); it rejoins in phase
  cut_dds,          // the end cap's DDS link to the host is cut (every datagram in and out); no endcap: all
  restore_dds,      // ... and restored
  release_spool,    // the spool runs free, the drive does not notice; params: motor
  seize_spool,      // the spool seizes (cable length frozen), the drive does not notice; params: motor
  // CANopen supervision (docs/design/canopen.md):
  reboot_drive,      // the drive power-cycles: boot-up, pre-operational, unpowered; params: motor
  reboot_load_cell,  // the load cell power-cycles
  // The node leaves NMT operational by itself and goes on beating (pre-operational /
  // stopped): no PDOs either way, no boot-up. drive_preoperational params: motor.
  drive_preoperational,
  load_cell_stopped,
  hang_loop,    // the end cap's control loop hangs, its process (DDS node) lives (test hook)
  stop_endcap,  // SIGSTOP: a dead end cap; its drives find out through their heartbeat consumer
  mute_dds,     // the end cap's DDS participant stops sending, for good, and still hears (a handshake
                // stalled one way); its rejoin clears it; no endcap: all
  // An operator's commands over DDS (the run's operator, HilOptions::operator_command),
  // acknowledged per end cap: no endcap: every end cap.
  estop,
  clear_fault,
  start,
};

const char* to_string(FaultKind kind);
// cut_dds, restore_dds, mute_dds: faults of the DDS link, which may name every end cap.
bool is_dds_link_fault(FaultKind kind);
// estop, clear_fault, start: an operator's commands, which may name every end cap.
bool is_operator_command(FaultKind kind);
// Either of the two: an event that may name every end cap (endcap -1).
bool may_name_every_endcap(FaultKind kind);

struct FaultParams {
  int motor = 0;                // -1: every motor of the end cap
  std::uint16_t code = 0x2310;  // EMCY error code (0x2310: continuous over-current)
  // A released drive lets its spool run free (brake off): the cable pays out to the
  // spool's end stop, the maximum rest length, and goes slack. Default: the drive
  // holds its cable (brake on), which is what a faulted CiA 402 drive does.
  bool release = false;
  double n_per_s = 5.0;      // load-cell drift
  double probability = 0.1;  // drop/corrupt
  double duration_s = 0.0;   // drop/corrupt: 0 = until the end
  CorruptKind corrupt_kind = CorruptKind::frame;
};

struct ScenarioEvent {
  double time_s = 0.0;
  int endcap = 0;  // -1: every end cap (DDS link faults only)
  FaultKind fault = FaultKind::drive_fault;
  FaultParams params;
  std::string describe() const;
};

struct Scenario {
  std::vector<ScenarioEvent> events;  // sorted by time
};

// Errors (std::runtime_error, via HilError) name the source and the event index.
Scenario parse_scenario(const std::string& json_text, int endcap_count, const std::string& source = "scenario");
Scenario load_scenario(const std::filesystem::path& path, int endcap_count);
// "ENDCAP:FAULT@TIME_S" (params default), e.g. "3:drive_fault@2.0"; ENDCAP "all"
// for the DDS link faults and the operator's commands.
ScenarioEvent parse_fault_option(const std::string& text, int endcap_count);
void sort_events(Scenario& scenario);
// What the parser cannot know: every end cap named is one of the robot's, and every
// motor named one its end cap has (one motor on a robot with 2 per end cap). Throws
// HilError naming the event, before anything starts rather than when it is due.
void check_scenario(const Scenario& scenario, const sim::Robot& robot);
// How a disabled cable fails (tensegrity hil --cable-failure).
enum class CableFailure : std::uint8_t {
  drive,  // its drive faults (EMCY) and releases it: slack; its end cap goes to its safe state (other cable held)
  spool,  // only the spool runs free (release_spool): slack; the end cap keeps playing its other cable
  seize,  // only the spool seizes (seize_spool): the cable keeps its start length; the end cap plays on
};
// Muscle failure from the start (the paper's Figure 13): cable `cable`, on the end
// cap that owns it, fails at time 0 in the given way. Throws HilError for a bad index.
ScenarioEvent disabled_cable_event(const sim::Robot& robot, int cable, CableFailure failure = CableFailure::drive);

}  // namespace tensegrity::hil
