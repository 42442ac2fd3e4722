// SPDX-License-Identifier: Apache-2.0
// Why an end cap refused a policy table or a command: the code travels in the ack
// (PolicyAck_::reason, CommandAck_::reason) next to its text, so a ground tool can
// both print it and act on it.
#pragma once

#include <cstdint>

#include "core/table.hpp"

namespace tensegrity::fw::comms {

enum class PolicyReason : std::uint8_t {
  accepted = 0,
  already_active = 1,  // a retry of the policy that already runs: accepted, nothing changes
  wrong_format_version = 2,
  wrong_endcap = 3,
  wrong_robot = 4,
  bad_motor_count = 5,
  bad_complexity = 6,
  bad_size = 7,
  bad_checksum = 8,
  bad_period = 9,
  bad_phase = 10,
  non_finite_value = 11,
  value_out_of_limits = 12,
  stale_version = 13,
  loop_busy = 14,  // the control loop did not take the table in time
  bad_policy_id = 15,
  storage_failed = 16,  // the table and its identity could not be made durable: nothing changed
};

enum class CommandReason : std::uint8_t {
  accepted = 0,
  wrong_format_version = 1,
  unknown_kind = 2,
  clock_not_synced = 3,  // a start needs the host's clock: no time-sync reply yet
  loop_not_running = 4,  // no telemetry from the control loop: cannot map the start time
  mailbox_full = 5,      // never for an emergency stop (a latched counter, no mailbox)
  out_of_order = 6,      // older than a command this writer already sent: not acted on
  stale = 7,             // a start issued longer ago than command_max_age_s (host time)
  bad_time = 8,          // a start's host time is outside the valid range
  estop_unseen = 9,      // a clear-fault sent before an emergency stop it had not seen
  // A start the control loop could not play (start_readiness.hpp), as it last published itself:
  fault_latched = 10,       // a fault is latched: the operator clears it first
  drives_not_enabled = 11,  // bring-up not done, or a drive not in operation enabled
  no_table = 12,            // no policy table loaded
};

const char* describe(PolicyReason reason) noexcept;
const char* describe(CommandReason reason) noexcept;
const char* to_string(PolicyReason reason) noexcept;  // identifier, for tables and JSON
bool is_accepted(PolicyReason reason) noexcept;
PolicyReason from_table_error(core::TableError error) noexcept;

}  // namespace tensegrity::fw::comms
