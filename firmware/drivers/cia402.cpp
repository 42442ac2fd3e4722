// SPDX-License-Identifier: Apache-2.0
#include "firmware/drivers/cia402.hpp"

namespace tensegrity::fw::canopen {

std::optional<InterpolationPeriod> interpolation_period(std::int64_t period_ns) {
  if (period_ns <= 0) return std::nullopt;
  std::int64_t value = period_ns;
  int index = -9;
  while (value % 10 == 0 && index < 0) {
    value /= 10;
    ++index;
  }
  if (value > 255) return std::nullopt;
  return InterpolationPeriod{static_cast<std::uint8_t>(value), static_cast<std::int8_t>(index)};
}

std::int64_t period_ns(InterpolationPeriod period) {
  if (period.index < -9 || period.index > 0) return -1;
  std::int64_t ns = period.value;
  for (int i = -9; i < period.index; ++i) ns *= 10;
  return ns;
}

const char* to_string(Cia402State state) {
  switch (state) {
    case Cia402State::not_ready_to_switch_on: return "not ready to switch on";
    case Cia402State::switch_on_disabled: return "switch on disabled";
    case Cia402State::ready_to_switch_on: return "ready to switch on";
    case Cia402State::switched_on: return "switched on";
    case Cia402State::operation_enabled: return "operation enabled";
    case Cia402State::quick_stop_active: return "quick stop active";
    case Cia402State::fault_reaction_active: return "fault reaction active";
    case Cia402State::fault: return "fault";
    case Cia402State::invalid: return "invalid statusword";
  }
  return "unknown";
}

const char* to_string(Cia402Command command) {
  switch (command) {
    case Cia402Command::shutdown: return "shutdown";
    case Cia402Command::switch_on: return "switch on";
    case Cia402Command::enable_operation: return "enable operation";
    case Cia402Command::disable_operation: return "disable operation";
    case Cia402Command::disable_voltage: return "disable voltage";
    case Cia402Command::quick_stop: return "quick stop";
    case Cia402Command::fault_reset: return "fault reset";
  }
  return "unknown";
}

// CiA 402 table 30: bit 6 switch on disabled, 5 quick stop, 3 fault, 2 operation
// enabled, 1 switched on, 0 ready to switch on.
Cia402State decode_statusword(std::uint16_t sw) {
  const unsigned m4f = sw & 0x4FU;
  const unsigned m6f = sw & 0x6FU;
  if (m4f == 0x00) return Cia402State::not_ready_to_switch_on;
  if (m4f == 0x40) return Cia402State::switch_on_disabled;
  if (m6f == 0x21) return Cia402State::ready_to_switch_on;
  if (m6f == 0x23) return Cia402State::switched_on;
  if (m6f == 0x27) return Cia402State::operation_enabled;
  if (m6f == 0x07) return Cia402State::quick_stop_active;
  if (m4f == 0x0F) return Cia402State::fault_reaction_active;
  if (m4f == 0x08) return Cia402State::fault;
  return Cia402State::invalid;
}

std::uint16_t statusword_bits(Cia402State state) {
  switch (state) {
    case Cia402State::not_ready_to_switch_on: return 0x0000;
    case Cia402State::switch_on_disabled: return 0x0040;
    case Cia402State::ready_to_switch_on: return 0x0021;
    case Cia402State::switched_on: return 0x0023;
    case Cia402State::operation_enabled: return 0x0027;
    case Cia402State::quick_stop_active: return 0x0007;
    case Cia402State::fault_reaction_active: return 0x000F;
    case Cia402State::fault: return 0x0008;
    case Cia402State::invalid: return 0x0001;
  }
  return 0x0001;
}

// CiA 402 table 48, bits 7, 3, 2, 1, 0.
std::uint16_t controlword_bits(Cia402Command command) {
  switch (command) {
    case Cia402Command::shutdown: return 0x0006;
    case Cia402Command::switch_on: return 0x0007;
    case Cia402Command::enable_operation: return 0x000F;
    case Cia402Command::disable_operation: return 0x0007;
    case Cia402Command::disable_voltage: return 0x0000;
    case Cia402Command::quick_stop: return 0x0002;
    case Cia402Command::fault_reset: return kCwFaultReset;
  }
  return 0x0000;
}

bool decode_controlword(std::uint16_t cw, Cia402Command& command) {
  if ((cw & kCwFaultReset) != 0) {
    command = Cia402Command::fault_reset;
    return true;
  }
  if ((cw & 0x02U) == 0) {
    command = Cia402Command::disable_voltage;
    return true;
  }
  if ((cw & 0x06U) == 0x02U) {
    command = Cia402Command::quick_stop;
    return true;
  }
  switch (cw & 0x0FU) {
    case 0x06:
    case 0x0E: command = Cia402Command::shutdown; return true;
    case 0x07: command = Cia402Command::switch_on; return true;  // or disable operation
    case 0x0F: command = Cia402Command::enable_operation; return true;
    default: return false;
  }
}

}  // namespace tensegrity::fw::canopen
