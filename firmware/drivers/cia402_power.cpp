// SPDX-License-Identifier: Apache-2.0
#include "firmware/drivers/cia402_power.hpp"

namespace tensegrity::fw::canopen {

std::uint16_t Cia402PowerControl::next_controlword(Cia402State state) {
  last_ = choose(state);
  return last_;
}

std::uint16_t Cia402PowerControl::choose(Cia402State state) {
  using C = Cia402Command;
  using S = Cia402State;
  if (state == S::fault) {
    // The drive resets on the rising edge of bit 7, so a held bit is dropped for
    // one cycle before being raised again.
    if (fault_reset_pending_ && (last_ & kCwFaultReset) == 0) return controlword_bits(C::fault_reset);
    return controlword_bits(C::disable_voltage);
  }
  if (state != S::fault_reaction_active) fault_reset_pending_ = false;
  switch (state) {
    case S::not_ready_to_switch_on:
    case S::fault_reaction_active:
    case S::invalid: return controlword_bits(C::disable_voltage);
    default: break;
  }
  switch (request_) {
    case PowerRequest::disabled: return controlword_bits(C::disable_voltage);
    case PowerRequest::quick_stop:
      return state == S::operation_enabled || state == S::quick_stop_active ? controlword_bits(C::quick_stop)
                                                                            : controlword_bits(C::disable_voltage);
    case PowerRequest::operation_enabled:
      switch (state) {
        case S::switch_on_disabled: return controlword_bits(C::shutdown);
        case S::ready_to_switch_on: return controlword_bits(C::switch_on);
        case S::switched_on:
        case S::operation_enabled: return controlword_bits(C::enable_operation);
        default: return controlword_bits(C::disable_voltage);  // quick stop active: leave via disabled
      }
  }
  return controlword_bits(C::disable_voltage);
}

}  // namespace tensegrity::fw::canopen
