// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/logic/start_readiness.hpp"

namespace tensegrity::fw::comms {

// The fault first: clearing it (the operator's call) also brings the drives back,
// so naming the drives would send the operator after a symptom.
CommandReason start_readiness(const LoopReadiness& loop) noexcept {
  if (loop.fault != core::FaultCause::none) return CommandReason::fault_latched;
  if (!loop.drives_enabled) return CommandReason::drives_not_enabled;
  if (!loop.has_table) return CommandReason::no_table;
  return CommandReason::accepted;
}

}  // namespace tensegrity::fw::comms
