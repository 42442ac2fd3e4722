// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/wire/reasons.hpp"

namespace tensegrity::fw::comms {

const char* describe(PolicyReason reason) noexcept {
  switch (reason) {
    case PolicyReason::accepted: return "accepted";
    case PolicyReason::already_active: return "accepted: this policy version is already active";
    case PolicyReason::wrong_format_version: return "message format version differs from this end cap's";
    case PolicyReason::wrong_endcap: return "table was built for another end cap";
    case PolicyReason::wrong_robot: return "table was built for another robot";
    case PolicyReason::bad_motor_count: return "motor count does not match this end cap";
    case PolicyReason::bad_complexity: return "complexity must be 1..16";
    case PolicyReason::bad_size: return "number of rest lengths is not motor_count x complexity";
    case PolicyReason::bad_checksum: return "checksum does not match the table";
    case PolicyReason::bad_period: return "period must be finite, > 0 and at most 3600 s";
    case PolicyReason::bad_phase: return "phase offset must be finite";
    case PolicyReason::non_finite_value: return "a rest length is not a finite number";
    case PolicyReason::value_out_of_limits: return "a rest length is outside the motor's limits";
    case PolicyReason::stale_version: return "version is not newer than the active policy (use force)";
    case PolicyReason::loop_busy: return "control loop did not take the table in time";
    case PolicyReason::bad_policy_id: return "policy id is empty";
    case PolicyReason::storage_failed: return "could not store the table durably: nothing changed";
  }
  return "unknown reason";
}

const char* to_string(PolicyReason reason) noexcept {
  switch (reason) {
    case PolicyReason::accepted: return "accepted";
    case PolicyReason::already_active: return "already_active";
    case PolicyReason::wrong_format_version: return "wrong_format_version";
    case PolicyReason::wrong_endcap: return "wrong_endcap";
    case PolicyReason::wrong_robot: return "wrong_robot";
    case PolicyReason::bad_motor_count: return "bad_motor_count";
    case PolicyReason::bad_complexity: return "bad_complexity";
    case PolicyReason::bad_size: return "bad_size";
    case PolicyReason::bad_checksum: return "bad_checksum";
    case PolicyReason::bad_period: return "bad_period";
    case PolicyReason::bad_phase: return "bad_phase";
    case PolicyReason::non_finite_value: return "non_finite_value";
    case PolicyReason::value_out_of_limits: return "value_out_of_limits";
    case PolicyReason::stale_version: return "stale_version";
    case PolicyReason::loop_busy: return "loop_busy";
    case PolicyReason::bad_policy_id: return "bad_policy_id";
    case PolicyReason::storage_failed: return "storage_failed";
  }
  return "unknown";
}

const char* describe(CommandReason reason) noexcept {
  switch (reason) {
    case CommandReason::accepted: return "accepted";
    case CommandReason::wrong_format_version: return "message format version differs from this end cap's";
    case CommandReason::unknown_kind: return "unknown command kind";
    case CommandReason::clock_not_synced: return "no time-sync reply from the host yet: cannot place the start time";
    case CommandReason::loop_not_running: return "no telemetry from the control loop: cannot place the start time";
    case CommandReason::mailbox_full: return "command mailbox to the control loop is full";
    case CommandReason::out_of_order: return "older than a command this writer already sent: not acted on";
    case CommandReason::stale: return "start issued too long ago (host time): not acted on";
    case CommandReason::bad_time: return "start time outside the valid range";
    case CommandReason::estop_unseen:
      return "an emergency stop reached this end cap after the sender last heard it: look again, then clear";
    case CommandReason::fault_latched: return "a fault is latched: the start would not play (tensegrity clear-fault)";
    case CommandReason::drives_not_enabled:
      return "drives not enabled (bring-up not done, or a drive not in operation enabled): the start would not play";
    case CommandReason::no_table: return "no policy table loaded: the start would not play (tensegrity upload)";
  }
  return "unknown reason";
}

bool is_accepted(PolicyReason reason) noexcept {
  return reason == PolicyReason::accepted || reason == PolicyReason::already_active;
}

PolicyReason from_table_error(core::TableError error) noexcept {
  switch (error) {
    case core::TableError::none: return PolicyReason::accepted;
    case core::TableError::bad_motor_count: return PolicyReason::bad_motor_count;
    case core::TableError::bad_complexity: return PolicyReason::bad_complexity;
    case core::TableError::bad_period: return PolicyReason::bad_period;
    case core::TableError::bad_phase: return PolicyReason::bad_phase;
    case core::TableError::non_finite_value: return PolicyReason::non_finite_value;
    case core::TableError::value_out_of_limits: return PolicyReason::value_out_of_limits;
  }
  return PolicyReason::value_out_of_limits;
}

}  // namespace tensegrity::fw::comms
