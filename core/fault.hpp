// SPDX-License-Identifier: Apache-2.0
#pragma once
#include <cstdint>

namespace tensegrity::core {

// Why an end cap went to its safe state (motors hold). Latched until cleared; the
// first cause is kept, later ones do not overwrite it.
enum class FaultCause : std::uint8_t {
  none = 0,
  over_tension,    // a measured tension above the hard limit
  drive_fault,     // the motor drive reported a fault (EMCY)
  drive_lost,      // the drive's heartbeat timed out
  sensor_timeout,  // the load cell stopped reporting
  host_lost,       // the host link was lost and the end cap is configured to stop
  emergency_stop,  // commanded by an operator
  bad_input,       // the caller broke the step contract (buffer sizes)
  // CANopen supervision (docs/design/canopen.md "Supervision"):
  node_rebooted,         // a drive or the load cell sent a boot-up after bring-up
  drive_disabled,        // a drive left operation enabled without being asked
  stale_position,        // no drive position newer than the configured age
  loop_stalled,          // the real-time loop missed cycles for longer than its drives wait for its heartbeat
  node_not_operational,  // a drive or the load cell left NMT operational after bring-up, still beating
};

const char* describe(FaultCause cause) noexcept;

}  // namespace tensegrity::core
