// SPDX-License-Identifier: Apache-2.0
#include "sim_devices.hpp"

#include "firmware/drivers/cob_id.hpp"
#include "firmware/drivers/emcy.hpp"
#include "firmware/drivers/sdo_abort.hpp"

namespace tensegrity::fw::sim {

using namespace canopen;

void SimNode::boot(std::int64_t now_ns, FrameOut& out) {
  powered_ = true;
  nmt_ = NmtState::pre_operational;
  out.push_back(encode_heartbeat(node_id_, NmtState::boot_up));
  next_heartbeat_ns_ = now_ns + script.heartbeat_period_ns;
}

void SimNode::tick(std::int64_t now_ns, FrameOut& out) {
  if (!powered_ || !script.heartbeat || now_ns < next_heartbeat_ns_) return;
  out.push_back(encode_heartbeat(node_id_, nmt_));
  next_heartbeat_ns_ = now_ns + script.heartbeat_period_ns;
}

void SimNode::on_frame(const CanFrame& frame, std::int64_t now_ns, FrameOut& out) {
  if (!powered_ || frame.extended || frame.rtr) return;
  NmtCommand command{};
  std::uint8_t target = 0;
  if (decode_nmt(frame, command, target)) {
    if (target != 0 && target != node_id_) return;
    switch (command) {
      case NmtCommand::start: nmt_ = NmtState::operational; break;
      case NmtCommand::stop: nmt_ = NmtState::stopped; break;
      case NmtCommand::enter_pre_operational: nmt_ = NmtState::pre_operational; break;
      case NmtCommand::reset_node:
        on_reset_node();
        boot(now_ns, out);
        break;
      case NmtCommand::reset_communication: boot(now_ns, out); break;
    }
    return;
  }
  if (frame.id == cob_id(Function::sdo_rx, node_id_)) {
    // SDO works in pre-operational and operational, not when stopped.
    if (nmt_ != NmtState::stopped) on_sdo_request(frame, out);
    return;
  }
  if (nmt_ == NmtState::operational) on_pdo_or_sync(frame, now_ns, out);
}

void SimNode::on_sdo_request(const CanFrame& frame, FrameOut& out) {
  SdoMessage request;
  if (!decode_sdo(frame, false, request)) return;
  if (request.kind == SdoKind::abort) return;  // the client gave up; nothing to answer
  ++sdo_requests;
  if (script.sdo_silent) return;
  SdoMessage reply{SdoKind::abort, request.address, 0, 4};
  if (script.sdo_abort_all != 0) {
    reply.value = script.sdo_abort_all;
  } else if (request.kind == SdoKind::upload_request) {
    std::uint32_t value = 0;
    std::uint8_t size = 0;
    const std::uint32_t abort = od_read(request.address, value, size);
    if (abort != 0) {
      reply.value = abort;
    } else if (script.sdo_segmented_upload) {
      CanFrame segmented = encode_sdo(node_id_, {SdoKind::upload_response, request.address, 100, 4});
      segmented.data[0] = 0x41;  // scs 2, e 0, s 1: 100 bytes follow in segments
      out.push_back(segmented);
      return;
    } else {
      reply = {SdoKind::upload_response, request.address, value, size};
    }
  } else if (request.kind == SdoKind::download_request) {
    const std::uint32_t abort = od_write(request.address, request.value, request.size);
    reply = abort != 0 ? SdoMessage{SdoKind::abort, request.address, abort, 4}
                       : SdoMessage{SdoKind::download_response, request.address, 0, 0};
  } else {
    reply.value = sdo_abort::kBadCommand;
  }
  out.push_back(encode_sdo(node_id_, reply));
}

// --- drive -------------------------------------------------------------------

std::uint16_t SimCia402Drive::statusword() const {
  std::uint16_t sw = statusword_bits(state_) | kSwRemote;
  switch (state_) {
    case Cia402State::ready_to_switch_on:
    case Cia402State::switched_on:
    case Cia402State::operation_enabled:
    case Cia402State::quick_stop_active:
      sw |= kSwVoltageEnabled;
      break;
    default:
      break;
  }
  return sw;
}

void SimCia402Drive::on_reset_node() {
  state_ = Cia402State::switch_on_disabled;
  mode_ = 0;
  last_controlword_ = 0;
}

void SimCia402Drive::inject_fault(std::uint16_t error_code, std::int64_t, FrameOut& out) {
  state_ = Cia402State::fault_reaction_active;
  pending_fault_code_ = error_code;
  out.push_back(encode_emcy(node_id(), {error_code, kErrRegGeneric | kErrRegCurrent, {1, 2, 3, 4, 5}}));
}

void SimCia402Drive::tick(std::int64_t now_ns, FrameOut& out) {
  if (state_ == Cia402State::fault_reaction_active) state_ = Cia402State::fault;
  SimNode::tick(now_ns, out);
}

void SimCia402Drive::apply_controlword(std::uint16_t cw) {
  controlwords.push_back(cw);
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
      if (pending_fault_code_ != 0) pending_fault_code_ = 0;
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
      if (c == C::enable_operation) state_ = S::operation_enabled;
      if (c == C::shutdown) state_ = S::ready_to_switch_on;
      if (c == C::disable_voltage || c == C::quick_stop) state_ = S::switch_on_disabled;
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
    default:
      break;
  }
}

void SimCia402Drive::on_pdo_or_sync(const CanFrame& frame, std::int64_t, FrameOut& out) {
  DriveRpdo1 rpdo;
  if (frame.id == cob_id(Function::rpdo1, node_id()) && decode_drive_rpdo1(frame, rpdo)) {
    apply_controlword(rpdo.controlword);
    target_counts_ = rpdo.target_position_counts;
    return;
  }
  std::uint8_t counter = 0;
  if (!decode_sync(frame, counter)) return;
  // CSP: the target latched at SYNC is reached within the cycle (an ideal drive).
  if (state_ == Cia402State::operation_enabled && mode_ == kModeCyclicSynchronousPosition) {
    velocity_counts_per_s_ = static_cast<std::int32_t>(static_cast<double>(target_counts_ - position_counts_) /
                                                       sync_period_s);
    position_counts_ = target_counts_;
  } else {
    velocity_counts_per_s_ = 0;
  }
  out.push_back(encode_drive_tpdo1(node_id(), {statusword(), position_counts_}));
  out.push_back(encode_drive_tpdo2(node_id(), {velocity_counts_per_s_, mode_}));
}

std::uint32_t SimCia402Drive::od_read(SdoAddress a, std::uint32_t& value, std::uint8_t& size) {
  const bool maybe_known = a.index == 0x1000 || (a.index >= kOdControlword && a.index <= kOdTargetPosition);
  if (!maybe_known) return sdo_abort::kNoObject;
  if (a.subindex != 0) return sdo_abort::kNoSubindex;
  switch (a.index) {
    case 0x1000: value = 0x0002'0192; size = 4; return 0;  // CiA 402 servo drive
    case kOdControlword: value = last_controlword_; size = 2; return 0;
    case kOdStatusword: value = statusword(); size = 2; return 0;
    case kOdModesOfOperation:
    case kOdModesOfOperationDisplay: value = static_cast<std::uint8_t>(mode_); size = 1; return 0;
    case kOdPositionActual: value = static_cast<std::uint32_t>(position_counts_); size = 4; return 0;
    case kOdVelocityActual: value = static_cast<std::uint32_t>(velocity_counts_per_s_); size = 4; return 0;
    case kOdTargetPosition: value = static_cast<std::uint32_t>(target_counts_); size = 4; return 0;
    default: return sdo_abort::kNoObject;
  }
}

std::uint32_t SimCia402Drive::od_write(SdoAddress a, std::uint32_t value, std::uint8_t size) {
  switch (a.index) {
    case kOdModesOfOperation: {
      if (a.subindex != 0) return sdo_abort::kNoSubindex;
      if (size != 1) return sdo_abort::kLengthMismatch;
      const auto mode = static_cast<std::int8_t>(value);
      if (mode != kModeCyclicSynchronousPosition && mode != 1) return sdo_abort::kValueRange;
      mode_ = mode;
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
    case kOdVelocityActual:
      return sdo_abort::kReadOnly;
    default:
      return sdo_abort::kNoObject;
  }
}

// --- load cell -----------------------------------------------------------------

std::uint32_t SimLoadCell::od_read(SdoAddress a, std::uint32_t& value, std::uint8_t& size) {
  if (a.index == 0x1000 && a.subindex == 0) {
    value = 0x0004'0194;  // CiA 404 measuring device, analogue input
    size = 4;
    return 0;
  }
  return sdo_abort::kNoObject;
}

std::uint32_t SimLoadCell::od_write(SdoAddress a, std::uint32_t, std::uint8_t) {
  return a.index == 0x1000 ? sdo_abort::kReadOnly : sdo_abort::kNoObject;
}

void SimLoadCell::on_pdo_or_sync(const CanFrame& frame, std::int64_t, FrameOut& out) {
  std::uint8_t counter = 0;
  if (!decode_sync(frame, counter)) return;
  if (advance_sequence) ++sample.sequence;
  out.push_back(encode_load_cell_tpdo1(node_id(), sample));
}

}  // namespace tensegrity::fw::sim
