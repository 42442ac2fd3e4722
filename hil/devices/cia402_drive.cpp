// SPDX-License-Identifier: Apache-2.0
#include "hil/devices/cia402_drive.hpp"

#include "firmware/drivers/cob_id.hpp"
#include "firmware/drivers/emcy.hpp"
#include "firmware/drivers/sdo_abort.hpp"

namespace tensegrity::hil {

using namespace fw::canopen;

std::uint16_t SimCia402Drive::statusword() const {
  std::uint16_t sw = statusword_bits(state_) | kSwRemote;
  switch (state_) {
    case Cia402State::ready_to_switch_on:
    case Cia402State::switched_on:
    case Cia402State::operation_enabled:
    case Cia402State::quick_stop_active: sw |= kSwVoltageEnabled; break;
    default: break;
  }
  return sw;
}

void SimCia402Drive::on_reset_node() {
  if (state_ == Cia402State::operation_enabled) left_enabled_ns_ = now_ns_;
  state_ = Cia402State::switch_on_disabled;
  mode_ = 0;
  last_controlword_ = 0;
  enable_requested_ = false;
  abort_option_ = AbortConnectionOption::fault_signal;
  cycle_period_us_ = 0;
  interpolation_ = {};
}

// CiA 402 abort connection: the end cap's heartbeat (0x1016) timed out.
void SimCia402Drive::on_heartbeat_lost(std::int64_t now_ns, FrameOut& out) {
  now_ns_ = now_ns;
  const bool was_enabled = state_ == Cia402State::operation_enabled;
  switch (abort_option_) {
    case AbortConnectionOption::no_action: return;
    case AbortConnectionOption::fault_signal:
      inject_fault(0x8130, now_ns, out);  // EMCY 0x8130: life guard / heartbeat error
      break;
    case AbortConnectionOption::disable_voltage: on_connection_lost(); break;
    case AbortConnectionOption::quick_stop:
      if (state_ == Cia402State::operation_enabled) state_ = Cia402State::quick_stop_active;
      enable_requested_ = false;
      break;
  }
  if (was_enabled && state_ != Cia402State::operation_enabled) left_enabled_ns_ = now_ns;
}

void SimCia402Drive::inject_fault(std::uint16_t error_code, std::int64_t, FrameOut& out) {
  state_ = Cia402State::fault_reaction_active;
  pending_fault_code_ = error_code;
  last_fault_code_ = error_code;
  enable_requested_ = false;
  ++emcy_sent_;
  if (!script.silent) {
    out.push_back(encode_emcy(node_id(), {error_code, kErrRegGeneric | kErrRegCurrent, {1, 2, 3, 4, 5}}));
  }
}

void SimCia402Drive::tick(std::int64_t now_ns, FrameOut& out) {
  now_ns_ = now_ns;
  if (state_ == Cia402State::fault_reaction_active) state_ = Cia402State::fault;
  SimNode::tick(now_ns, out);
}

void SimCia402Drive::set_actual(std::int32_t position_counts, std::int32_t velocity_counts_per_s) {
  position_counts_ = position_counts;
  velocity_counts_per_s_ = velocity_counts_per_s;
}

void SimCia402Drive::emit_tpdos(FrameOut& out) const {
  // Synchronous PDOs exist only in operational (CiA 301).
  if (!answering() || nmt_state() != NmtState::operational) return;
  out.push_back(encode_drive_tpdo1(node_id(), {statusword(), position_counts_}));
  out.push_back(encode_drive_tpdo2(node_id(), {velocity_counts_per_s_, mode_}));
}

bool SimCia402Drive::at_enable_gate() const {
  return state_ == Cia402State::switched_on && enable_requested_ && answering();
}

void SimCia402Drive::release_enable_gate() {
  // The gate stopped this end cap's time (no SYNC, no cycle, no heartbeat from it):
  // that pause is the emulator's, not a silent end cap.
  restart_consumer_timer();
  if (at_enable_gate()) state_ = Cia402State::operation_enabled;
  enable_requested_ = false;
}

void SimCia402Drive::on_connection_lost() {
  if (state_ != Cia402State::fault && state_ != Cia402State::fault_reaction_active) {
    state_ = Cia402State::switch_on_disabled;
  }
  enable_requested_ = false;
}

bool SimCia402Drive::follows_target() const {
  return answering() && state_ == Cia402State::operation_enabled && mode_ == kModeCyclicSynchronousPosition;
}

void SimCia402Drive::apply_controlword(std::uint16_t cw) {
  const bool was_enabled = state_ == Cia402State::operation_enabled;
  apply_controlword_to_state(cw);
  if (was_enabled && state_ != Cia402State::operation_enabled) left_enabled_ns_ = now_ns_;
}

void SimCia402Drive::apply_controlword_to_state(std::uint16_t cw) {
  if (log_controlwords) controlwords.push_back(cw);
  Cia402Command c{};
  const bool known = decode_controlword(cw, c);
  const bool reset_edge = (cw & kCwFaultReset) != 0 && (last_controlword_ & kCwFaultReset) == 0;
  last_controlword_ = cw;
  if (!known) return;
  using S = Cia402State;
  using C = Cia402Command;
  if (state_ == S::fault) {
    if (reset_edge) {
      state_ = S::switch_on_disabled;
      pending_fault_code_ = 0;
    }
    return;
  }
  if (state_ == S::fault_reaction_active || c == C::fault_reset) return;
  switch (state_) {
    case S::switch_on_disabled:
      if (c == C::shutdown) state_ = S::ready_to_switch_on;
      break;
    case S::ready_to_switch_on:
      if (c == C::switch_on || c == C::enable_operation) state_ = S::switched_on;
      if (c == C::disable_voltage || c == C::quick_stop) state_ = S::switch_on_disabled;
      break;
    case S::switched_on:
      if (c == C::enable_operation) {
        if (hold_enable) {
          enable_requested_ = true;
        } else {
          state_ = S::operation_enabled;
        }
      }
      if (c == C::shutdown) state_ = S::ready_to_switch_on;
      if (c == C::disable_voltage || c == C::quick_stop) state_ = S::switch_on_disabled;
      if (c != C::enable_operation) enable_requested_ = false;
      break;
    case S::operation_enabled:
      if (c == C::switch_on) state_ = S::switched_on;  // disable operation
      if (c == C::shutdown) state_ = S::ready_to_switch_on;
      if (c == C::disable_voltage) state_ = S::switch_on_disabled;
      if (c == C::quick_stop) state_ = S::quick_stop_active;
      break;
    case S::quick_stop_active:
      if (c == C::disable_voltage) state_ = S::switch_on_disabled;
      if (c == C::enable_operation) state_ = S::operation_enabled;
      break;
    default: break;
  }
}

void SimCia402Drive::on_pdo_or_sync(const CanFrame& frame, std::int64_t now_ns, FrameOut& out) {
  now_ns_ = now_ns;
  DriveRpdo1 rpdo;
  if (frame.id == cob_id(Function::rpdo1, node_id()) && decode_drive_rpdo1(frame, rpdo)) {
    ++rpdos_received_;
    apply_controlword(rpdo.controlword);
    target_counts_ = rpdo.target_position_counts;
    return;
  }
  std::uint8_t counter = 0;
  if (!decode_sync(frame, counter)) return;
  if (ideal_position) {
    // CSP: the target latched at SYNC is reached within the cycle (an ideal drive).
    if (state_ == Cia402State::operation_enabled && mode_ == kModeCyclicSynchronousPosition) {
      velocity_counts_per_s_ = static_cast<std::int32_t>(static_cast<double>(target_counts_ - position_counts_) * 1e9 /
                                                         static_cast<double>(interpolation_period_ns()));
      position_counts_ = target_counts_;
    } else {
      velocity_counts_per_s_ = 0;
    }
  }
  if (tpdo_on_sync) emit_tpdos(out);
}

std::uint32_t SimCia402Drive::od_read(SdoAddress a, std::uint32_t& value, std::uint8_t& size) {
  if (a.index == kOdAbortConnectionOption) {
    if (a.subindex != 0) return sdo_abort::kNoSubindex;
    value = static_cast<std::uint16_t>(abort_option_);
    size = 2;
    return 0;
  }
  if (a.index == kOdCommunicationCyclePeriod || a.index == kOdInterpolationTimePeriod)
    return read_period(a, value, size);
  const bool maybe_known = a.index == 0x1000 || (a.index >= kOdControlword && a.index <= kOdTargetPosition);
  if (!maybe_known) return sdo_abort::kNoObject;
  if (a.subindex != 0) return sdo_abort::kNoSubindex;
  switch (a.index) {
    case 0x1000:
      value = 0x0002'0192;
      size = 4;
      return 0;  // CiA 402 servo drive
    case kOdControlword:
      value = last_controlword_;
      size = 2;
      return 0;
    case kOdStatusword:
      value = statusword();
      size = 2;
      return 0;
    case kOdModesOfOperation:
    case kOdModesOfOperationDisplay:
      value = static_cast<std::uint8_t>(mode_);
      size = 1;
      return 0;
    case kOdPositionActual:
      value = static_cast<std::uint32_t>(position_counts_);
      size = 4;
      return 0;
    case kOdVelocityActual:
      value = static_cast<std::uint32_t>(velocity_counts_per_s_);
      size = 4;
      return 0;
    case kOdTargetPosition:
      value = static_cast<std::uint32_t>(target_counts_);
      size = 4;
      return 0;
    default: return sdo_abort::kNoObject;
  }
}

std::uint32_t SimCia402Drive::read_period(SdoAddress a, std::uint32_t& value, std::uint8_t& size) const {
  if (a.index == kOdCommunicationCyclePeriod) {
    if (a.subindex != 0) return sdo_abort::kNoSubindex;
    value = cycle_period_us_;
    size = 4;
    return 0;
  }
  size = 1;
  switch (a.subindex) {
    case 0: value = 2; return 0;  // highest sub-index
    case 1: value = interpolation_.value; return 0;
    case 2: value = static_cast<std::uint8_t>(interpolation_.index); return 0;
    default: return sdo_abort::kNoSubindex;
  }
}

std::uint32_t SimCia402Drive::write_period(SdoAddress a, std::uint32_t value, std::uint8_t size) {
  if (a.index == kOdCommunicationCyclePeriod) {
    if (a.subindex != 0) return sdo_abort::kNoSubindex;
    if (size != 4) return sdo_abort::kLengthMismatch;
    cycle_period_us_ = value;
    return 0;
  }
  if (a.subindex != 1 && a.subindex != 2) return a.subindex == 0 ? sdo_abort::kReadOnly : sdo_abort::kNoSubindex;
  if (size != 1) return sdo_abort::kLengthMismatch;
  canopen::InterpolationPeriod next = interpolation_;
  if (a.subindex == 1) {
    next.value = static_cast<std::uint8_t>(value);
  } else {
    next.index = static_cast<std::int8_t>(value & 0xFFU);
  }
  // Each sub-index is written alone, so each write must leave a period the drive
  // can run at: a value of 0 or an index outside -9..0 is refused.
  if (next.value == 0 || canopen::period_ns(next) < 0) return sdo_abort::kValueRange;
  interpolation_ = next;
  return 0;
}

std::uint32_t SimCia402Drive::od_write(SdoAddress a, std::uint32_t value, std::uint8_t size) {
  if (a.index == kOdCommunicationCyclePeriod || a.index == kOdInterpolationTimePeriod)
    return write_period(a, value, size);
  switch (a.index) {
    case kOdModesOfOperation: {
      if (a.subindex != 0) return sdo_abort::kNoSubindex;
      if (size != 1) return sdo_abort::kLengthMismatch;
      const auto mode = static_cast<std::int8_t>(value);
      if (mode != kModeCyclicSynchronousPosition && mode != 1) return sdo_abort::kValueRange;
      mode_ = mode;
      return 0;
    }
    case kOdAbortConnectionOption: {
      if (a.subindex != 0) return sdo_abort::kNoSubindex;
      if (size != 2) return sdo_abort::kLengthMismatch;
      const auto option = static_cast<std::int16_t>(value & 0xFFFFU);
      if (option < 0 || option > 3) return sdo_abort::kValueRange;  // manufacturer codes: none here
      abort_option_ = static_cast<AbortConnectionOption>(option);
      return 0;
    }
    case kOdControlword:
      if (size != 2) return sdo_abort::kLengthMismatch;
      apply_controlword(static_cast<std::uint16_t>(value));
      return 0;
    case 0x1000:
    case kOdStatusword:
    case kOdModesOfOperationDisplay:
    case kOdPositionActual:
    case kOdVelocityActual: return sdo_abort::kReadOnly;
    default: return sdo_abort::kNoObject;
  }
}

}  // namespace tensegrity::hil
