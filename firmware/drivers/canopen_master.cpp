// SPDX-License-Identifier: Apache-2.0
#include "firmware/drivers/canopen_master.hpp"

#include <cmath>
#include <cstdio>

#include "firmware/drivers/cob_id.hpp"
#include "firmware/drivers/pdo_codec.hpp"
#include "firmware/drivers/sdo_abort.hpp"

namespace tensegrity::fw::canopen {

const char* to_string(MasterEventKind kind) {
  switch (kind) {
    case MasterEventKind::boot_up: return "boot-up";
    case MasterEventKind::heartbeat_lost: return "heartbeat lost";
    case MasterEventKind::heartbeat_restored: return "heartbeat restored";
    case MasterEventKind::emcy: return "emergency";
    case MasterEventKind::drive_fault: return "drive fault";
    case MasterEventKind::drive_fault_cleared: return "drive fault cleared";
    case MasterEventKind::sdo_finished: return "SDO finished";
    case MasterEventKind::bring_up_done: return "bring-up done";
    case MasterEventKind::bring_up_failed: return "bring-up failed";
  }
  return "unknown";
}

const char* to_string(BringUpStep step) {
  switch (step) {
    case BringUpStep::idle: return "idle";
    case BringUpStep::wait_boot: return "waiting for boot-up";
    case BringUpStep::set_mode: return "setting mode CSP";
    case BringUpStep::check_mode: return "checking mode";
    case BringUpStep::start_nodes: return "starting nodes";
    case BringUpStep::enable: return "enabling drive";
    case BringUpStep::done: return "done";
    case BringUpStep::failed: return "failed";
  }
  return "unknown";
}

const char* to_string(RxDrop reason) {
  switch (reason) {
    case RxDrop::extended_id: return "extended id";
    case RxDrop::rtr: return "remote frame";
    case RxDrop::unexpected_function: return "unexpected function";
    case RxDrop::unknown_node: return "unknown node";
    case RxDrop::bad_length: return "bad length";
    case RxDrop::bad_value: return "value out of range";
    case RxDrop::unexpected_sdo: return "unexpected SDO response";
    case RxDrop::count: break;
  }
  return "unknown";
}

CanopenMaster::CanopenMaster(CanBus& bus, const CanopenMasterConfig& config)
    : bus_(bus),
      config_(config),
      drive_hb_(config.drive_heartbeat_timeout_ns),
      load_cell_hb_(config.load_cell_heartbeat_timeout_ns),
      drive_sdo_(config.drive_node_id, config.sdo_timeout_ns),
      load_cell_sdo_(config.load_cell_node_id, config.sdo_timeout_ns) {}

bool CanopenMaster::role_of(std::uint8_t id, NodeRole& role) const {
  if (id == config_.drive_node_id) {
    role = NodeRole::drive;
    return true;
  }
  if (config_.use_load_cell && id == config_.load_cell_node_id) {
    role = NodeRole::load_cell;
    return true;
  }
  return false;
}

void CanopenMaster::emit(MasterEventKind kind, std::uint8_t id, std::int64_t now_ns) {
  MasterEvent e;
  e.kind = kind;
  e.node_id = id;
  e.time_ns = now_ns;
  events_.push(e);
}

void CanopenMaster::on_frame(const CanFrame& frame, std::int64_t now_ns) {
  if (frame.extended) return drop(RxDrop::extended_id);
  if (frame.rtr) return drop(RxDrop::rtr);
  if (frame.id == kSyncCobId) return on_sync(frame, now_ns);
  const Function function = function_of(frame.id);
  switch (function) {
    case Function::heartbeat:
    case Function::sync_or_emcy:
    case Function::tpdo1:
    case Function::tpdo2:
    case Function::sdo_tx:
      break;
    default:
      return drop(RxDrop::unexpected_function);
  }
  NodeRole role = NodeRole::drive;
  if (!role_of(node_of(frame.id), role)) return drop(RxDrop::unknown_node);
  switch (function) {
    case Function::heartbeat: return on_heartbeat(frame, role, now_ns);
    case Function::sync_or_emcy: return on_emcy(frame, role, now_ns);
    case Function::tpdo1:
      return role == NodeRole::drive ? on_drive_tpdo1(frame, now_ns) : on_load_cell_tpdo1(frame, now_ns);
    case Function::tpdo2:
      if (role != NodeRole::drive) return drop(RxDrop::unexpected_function);
      return on_drive_tpdo2(frame, now_ns);
    case Function::sdo_tx: return on_sdo(frame, role, now_ns);
    default: return drop(RxDrop::unexpected_function);
  }
}

void CanopenMaster::on_sync(const CanFrame& frame, std::int64_t now_ns) {
  std::uint8_t counter = 0;
  if (frame.dlc > 1) return drop(RxDrop::bad_length);
  if (!decode_sync(frame, counter)) return drop(RxDrop::bad_value);
  ++sync_.received;
  sync_.last_counter = counter;
  sync_.last_received_ns = now_ns;
  accept();
}

void CanopenMaster::on_heartbeat(const CanFrame& frame, NodeRole role, std::int64_t now_ns) {
  if (frame.dlc != 1) return drop(RxDrop::bad_length);
  NmtState state = NmtState::unknown;
  if (!decode_nmt_state(frame.data[0], state)) return drop(RxDrop::bad_value);
  accept();
  HeartbeatMonitor& hb = role == NodeRole::drive ? drive_hb_ : load_cell_hb_;
  switch (hb.on_heartbeat(state, now_ns)) {
    case HeartbeatMonitor::Change::boot_up: emit(MasterEventKind::boot_up, node_id(role), now_ns); break;
    case HeartbeatMonitor::Change::restored:
      emit(MasterEventKind::heartbeat_restored, node_id(role), now_ns);
      break;
    default: break;
  }
}

void CanopenMaster::on_emcy(const CanFrame& frame, NodeRole role, std::int64_t now_ns) {
  EmcyMessage emcy;
  if (!decode_emcy(frame, emcy)) return drop(RxDrop::bad_length);
  accept();
  if (role == NodeRole::drive) {
    drive_.has_emcy = true;
    drive_.last_emcy = emcy;
  } else {
    load_cell_.has_emcy = true;
    load_cell_.last_emcy = emcy;
  }
  MasterEvent e;
  e.kind = MasterEventKind::emcy;
  e.node_id = node_id(role);
  e.time_ns = now_ns;
  e.emcy = emcy;
  events_.push(e);
}

void CanopenMaster::on_drive_tpdo1(const CanFrame& frame, std::int64_t now_ns) {
  if (frame.dlc != kDriveTpdo1Bytes) return drop(RxDrop::bad_length);
  DriveTpdo1 pdo;
  if (!decode_drive_tpdo1(frame, pdo)) return drop(RxDrop::bad_length);
  const Cia402State state = decode_statusword(pdo.statusword);
  if (state == Cia402State::invalid) return drop(RxDrop::bad_value);
  accept();
  const auto in_fault = [](Cia402State s) {
    return s == Cia402State::fault || s == Cia402State::fault_reaction_active;
  };
  const bool was_fault = drive_.seen && in_fault(drive_.state);
  drive_.seen = true;
  drive_.statusword = pdo.statusword;
  drive_.state = state;
  drive_.position_counts = pdo.actual_position_counts;
  drive_.rest_length_m = config_.spool.rest_length_from_counts(pdo.actual_position_counts);
  drive_.position_updated_ns = now_ns;
  if (in_fault(state) && !was_fault) emit(MasterEventKind::drive_fault, config_.drive_node_id, now_ns);
  if (!in_fault(state) && was_fault) emit(MasterEventKind::drive_fault_cleared, config_.drive_node_id, now_ns);
}

void CanopenMaster::on_drive_tpdo2(const CanFrame& frame, std::int64_t now_ns) {
  if (frame.dlc != kDriveTpdo2Bytes) return drop(RxDrop::bad_length);
  DriveTpdo2 pdo;
  if (!decode_drive_tpdo2(frame, pdo)) return drop(RxDrop::bad_length);
  accept();
  drive_.velocity_counts_per_s = pdo.actual_velocity_counts_per_s;
  drive_.rest_length_rate_m_per_s = config_.spool.rate_from_counts_per_s(pdo.actual_velocity_counts_per_s);
  drive_.mode_display = pdo.mode_display;
  drive_.velocity_updated_ns = now_ns;
}

void CanopenMaster::on_load_cell_tpdo1(const CanFrame& frame, std::int64_t now_ns) {
  if (frame.dlc != kLoadCellTpdo1Bytes) return drop(RxDrop::bad_length);
  LoadCellTpdo1 pdo;
  if (!decode_load_cell_tpdo1(frame, pdo)) return drop(RxDrop::bad_value);
  accept();
  if (load_cell_.seen && pdo.sequence == load_cell_.sequence) ++load_cell_.stale_samples;
  load_cell_.seen = true;
  load_cell_.status = pdo.status;
  load_cell_.sequence = pdo.sequence;
  load_cell_.updated_ns = now_ns;
  const bool adc_ok = (pdo.status & kLoadCellAdcFault) == 0;
  constexpr std::array<std::uint8_t, 2> kValid = {kLoadCellCh0Valid, kLoadCellCh1Valid};
  constexpr std::array<std::uint8_t, 2> kOver = {kLoadCellCh0OverRange, kLoadCellCh1OverRange};
  for (std::size_t ch = 0; ch < 2; ++ch) {
    load_cell_.tension_n[ch] = static_cast<double>(pdo.tension_mn[ch]) * 1e-3;
    load_cell_.valid[ch] = adc_ok && (pdo.status & kValid[ch]) != 0 && (pdo.status & kOver[ch]) == 0;
  }
}

void CanopenMaster::on_sdo(const CanFrame& frame, NodeRole role, std::int64_t now_ns) {
  CanFrame abort;
  bool send_abort = false;
  switch (sdo_client(role).on_response(frame, now_ns, abort, send_abort)) {
    case SdoRx::completed:
      accept();
      emit(MasterEventKind::sdo_finished, node_id(role), now_ns);
      break;
    case SdoRx::unexpected: drop(RxDrop::unexpected_sdo); break;
    case SdoRx::malformed:
      drop(frame.dlc != 8 ? RxDrop::bad_length : RxDrop::bad_value);
      if (send_abort) {
        bus_.send(abort);
        emit(MasterEventKind::sdo_finished, node_id(role), now_ns);
      }
      break;
  }
}

void CanopenMaster::poll(std::int64_t now_ns) {
  if (drive_hb_.poll(now_ns) == HeartbeatMonitor::Change::lost) {
    emit(MasterEventKind::heartbeat_lost, config_.drive_node_id, now_ns);
  }
  if (config_.use_load_cell && load_cell_hb_.poll(now_ns) == HeartbeatMonitor::Change::lost) {
    emit(MasterEventKind::heartbeat_lost, config_.load_cell_node_id, now_ns);
  }
  for (const NodeRole role : {NodeRole::drive, NodeRole::load_cell}) {
    CanFrame abort;
    if (sdo_client(role).poll(now_ns, abort)) {
      bus_.send(abort);
      emit(MasterEventKind::sdo_finished, node_id(role), now_ns);
    }
  }
  step_bring_up(now_ns);
}

CanResult CanopenMaster::write_target(double rest_length_m) {
  const bool finite = std::isfinite(rest_length_m);
  if (!finite) ++targets_refused_;
  const std::uint16_t cw = power_.next_controlword(drive_.state);
  const bool follow = finite && drive_.state == Cia402State::operation_enabled;
  const std::int32_t target =
      follow ? config_.spool.counts_from_rest_length(rest_length_m) : drive_.position_counts;
  drive_.controlword_sent = cw;
  drive_.target_sent_counts = target;
  return bus_.send(encode_drive_rpdo1(config_.drive_node_id, {cw, target}));
}

CanResult CanopenMaster::send_sync() {
  std::uint8_t counter = 0;
  if (config_.sync_counter_max >= 2) {
    counter = next_sync_counter_;
    next_sync_counter_ = counter >= config_.sync_counter_max ? 1 : static_cast<std::uint8_t>(counter + 1);
  }
  const CanResult r = bus_.send(encode_sync(counter));
  if (r == CanResult::ok) ++sync_.sent;
  return r;
}

CanResult CanopenMaster::send_nmt(NmtCommand command, std::uint8_t id) {
  return bus_.send(encode_nmt(command, id));
}

bool CanopenMaster::sdo_upload(NodeRole node, SdoAddress address, std::int64_t now_ns) {
  if (node == NodeRole::load_cell && !config_.use_load_cell) return false;
  CanFrame request;
  if (!sdo_client(node).start_upload(address, now_ns, request)) return false;
  bus_.send(request);
  return true;
}

bool CanopenMaster::sdo_download(NodeRole node, SdoAddress address, std::uint32_t value, std::uint8_t size_bytes,
                                 std::int64_t now_ns) {
  if (node == NodeRole::load_cell && !config_.use_load_cell) return false;
  CanFrame request;
  if (!sdo_client(node).start_download(address, value, size_bytes, now_ns, request)) return false;
  bus_.send(request);
  return true;
}

}  // namespace tensegrity::fw::canopen
