// SPDX-License-Identifier: Apache-2.0
// Whether the control loop, as it last published itself, can take a start. The
// loop refuses a start it cannot play (no table, drives not enabled, a fault
// latched) one cycle after the node acked it, and nothing on the wire said so: the
// host saw "accepted" and an end cap that stayed idle. The node judges the same
// state first, so the ack carries the reason. The loop still has the last word (its
// state may change between the ack and the start time); the ground tool's look at
// telemetry after the start time catches that.
#pragma once

#include "firmware/comms/wire/reasons.hpp"
#include "core/fault.hpp"

namespace tensegrity::fw::comms {

// The loop's last published state, as the node's command listener sees it.
struct LoopReadiness {
  bool drives_enabled = false;  // bring-up done, every drive operation enabled
  core::FaultCause fault = core::FaultCause::none;
  bool has_table = false;  // a policy table is loaded in the controller
};

// accepted, or the first reason the loop would refuse a start: a latched fault
// (clearing it is the operator's), then the drives, then the table.
CommandReason start_readiness(const LoopReadiness& loop) noexcept;

}  // namespace tensegrity::fw::comms
