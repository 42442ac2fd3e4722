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
    case BringUpStep::set_heartbeat_producer: return "setting heartbeat producer time";
    case BringUpStep::set_mode: return "setting mode CSP";
    case BringUpStep::check_mode: return "checking mode";
    case BringUpStep::set_cycle_period: return "setting communication cycle period";
    case BringUpStep::set_interpolation_value:
    case BringUpStep::set_interpolation_index: return "setting interpolation time period";
    case BringUpStep::set_heartbeat_consumer: return "configuring heartbeat consumer";
    case BringUpStep::set_abort_connection: return "setting abort connection option";
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

std::array<CanopenMaster::DriveNode, kMaxDriveNodes> CanopenMaster::make_drives(const CanopenMasterConfig& c) {
  static_assert(kMaxDriveNodes == 4, "list one DriveNode per possible drive");
  return {DriveNode(c.drive_node(0), c), DriveNode(c.drive_node(1), c), DriveNode(c.drive_node(2), c),
          DriveNode(c.drive_node(3), c)};
}

// A drive count outside 1..kMaxDriveNodes is clamped rather than thrown on: the
// application validates its configuration before it builds the master.
CanopenMaster::CanopenMaster(CanBus& bus, const CanopenMasterConfig& config)
    : bus_(bus),
      config_(config),
      drive_count_(
          config.drive_count < 1 ? 1 : (config.drive_count > kMaxDriveNodes ? kMaxDriveNodes : config.drive_count)),
      drives_(make_drives(config)),
      load_cell_hb_(config.load_cell_heartbeat_timeout_ns),
      load_cell_sdo_(config.load_cell_node_id, config.sdo_timeout_ns) {}

bool CanopenMaster::node_ref(std::uint8_t id, NodeRef& node) const {
  for (std::size_t i = 0; i < drive_count_; ++i) {
    if (id == config_.drive_node(i)) {
      node = NodeRef{NodeRole::drive, i};
      return true;
    }
  }
  if (config_.use_load_cell && id == config_.load_cell_node_id) {
    node = NodeRef{NodeRole::load_cell, 0};
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
    case Function::sdo_tx: break;
    default: return drop(RxDrop::unexpected_function);
  }
  NodeRef node;
  if (!node_ref(node_of(frame.id), node)) return drop(RxDrop::unknown_node);
  const bool is_drive = node.role == NodeRole::drive;
  switch (function) {
    case Function::heartbeat: return on_heartbeat(frame, node, now_ns);
    case Function::sync_or_emcy: return on_emcy(frame, node, now_ns);
    case Function::tpdo1:
      return is_drive ? on_drive_tpdo1(frame, node.drive_index, now_ns) : on_load_cell_tpdo1(frame, now_ns);
    case Function::tpdo2:
      if (!is_drive) return drop(RxDrop::unexpected_function);
      return on_drive_tpdo2(frame, node.drive_index, now_ns);
    case Function::sdo_tx: return on_sdo(frame, node, now_ns);
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

void CanopenMaster::on_heartbeat(const CanFrame& frame, NodeRef node, std::int64_t now_ns) {
  if (frame.dlc != 1) return drop(RxDrop::bad_length);
  NmtState state = NmtState::unknown;
  if (!decode_nmt_state(frame.data[0], state)) return drop(RxDrop::bad_value);
  accept();
  HeartbeatMonitor& hb = node.role == NodeRole::drive ? drives_[node.drive_index].hb : load_cell_hb_;
  switch (hb.on_heartbeat(state, now_ns)) {
    case HeartbeatMonitor::Change::boot_up: emit(MasterEventKind::boot_up, node_id(node), now_ns); break;
    case HeartbeatMonitor::Change::restored: emit(MasterEventKind::heartbeat_restored, node_id(node), now_ns); break;
    default: break;
  }
}

void CanopenMaster::on_emcy(const CanFrame& frame, NodeRef node, std::int64_t now_ns) {
  EmcyMessage emcy;
  if (!decode_emcy(frame, emcy)) return drop(RxDrop::bad_length);
  accept();
  if (node.role == NodeRole::drive) {
    drives_[node.drive_index].status.has_emcy = true;
    drives_[node.drive_index].status.last_emcy = emcy;
  } else {
    load_cell_.has_emcy = true;
    load_cell_.last_emcy = emcy;
  }
  MasterEvent e;
  e.kind = MasterEventKind::emcy;
  e.node_id = node_id(node);
  e.time_ns = now_ns;
  e.emcy = emcy;
  events_.push(e);
}

void CanopenMaster::on_drive_tpdo1(const CanFrame& frame, std::size_t drive_index, std::int64_t now_ns) {
  if (frame.dlc != kDriveTpdo1Bytes) return drop(RxDrop::bad_length);
  DriveTpdo1 pdo;
  if (!decode_drive_tpdo1(frame, pdo)) return drop(RxDrop::bad_length);
  const Cia402State state = decode_statusword(pdo.statusword);
  if (state == Cia402State::invalid) return drop(RxDrop::bad_value);
  accept();
  const auto in_fault = [](Cia402State s) {
    return s == Cia402State::fault || s == Cia402State::fault_reaction_active;
  };
  DriveStatus& ds = drives_[drive_index].status;
  const std::uint8_t id = config_.drive_node(drive_index);
  const bool was_fault = ds.seen && in_fault(ds.state);
  ds.seen = true;
  ds.statusword = pdo.statusword;
  ds.state = state;
  ds.position_counts = pdo.actual_position_counts;
  ds.rest_length_m = config_.spool.rest_length_from_counts(pdo.actual_position_counts);
  ds.position_updated_ns = now_ns;
  if (in_fault(state) && !was_fault) emit(MasterEventKind::drive_fault, id, now_ns);
  if (!in_fault(state) && was_fault) emit(MasterEventKind::drive_fault_cleared, id, now_ns);
}

void CanopenMaster::on_drive_tpdo2(const CanFrame& frame, std::size_t drive_index, std::int64_t now_ns) {
  if (frame.dlc != kDriveTpdo2Bytes) return drop(RxDrop::bad_length);
  DriveTpdo2 pdo;
  if (!decode_drive_tpdo2(frame, pdo)) return drop(RxDrop::bad_length);
  accept();
  DriveStatus& ds = drives_[drive_index].status;
  ds.velocity_counts_per_s = pdo.actual_velocity_counts_per_s;
  ds.rest_length_rate_m_per_s = config_.spool.rate_from_counts_per_s(pdo.actual_velocity_counts_per_s);
  ds.mode_display = pdo.mode_display;
  ds.velocity_updated_ns = now_ns;
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

void CanopenMaster::on_sdo(const CanFrame& frame, NodeRef node, std::int64_t now_ns) {
  CanFrame abort;
  bool send_abort = false;
  switch (sdo_client(node).on_response(frame, now_ns, abort, send_abort)) {
    case SdoRx::completed:
      accept();
      emit(MasterEventKind::sdo_finished, node_id(node), now_ns);
      break;
    case SdoRx::unexpected: drop(RxDrop::unexpected_sdo); break;
    case SdoRx::malformed:
      drop(frame.dlc != 8 ? RxDrop::bad_length : RxDrop::bad_value);
      if (send_abort) {
        bus_.send(abort);
        emit(MasterEventKind::sdo_finished, node_id(node), now_ns);
      }
      break;
  }
}

void CanopenMaster::poll(std::int64_t now_ns) {
  for (std::size_t i = 0; i < drive_count_; ++i) {
    if (drives_[i].hb.poll(now_ns) == HeartbeatMonitor::Change::lost) {
      emit(MasterEventKind::heartbeat_lost, config_.drive_node(i), now_ns);
    }
  }
  if (config_.use_load_cell && load_cell_hb_.poll(now_ns) == HeartbeatMonitor::Change::lost) {
    emit(MasterEventKind::heartbeat_lost, config_.load_cell_node_id, now_ns);
  }
  const auto poll_sdo = [&](NodeRef node) {
    CanFrame abort;
    if (sdo_client(node).poll(now_ns, abort)) {
      bus_.send(abort);
      emit(MasterEventKind::sdo_finished, node_id(node), now_ns);
    }
  };
  for (std::size_t i = 0; i < drive_count_; ++i) poll_sdo(NodeRef{NodeRole::drive, i});
  poll_sdo(NodeRef{NodeRole::load_cell, 0});
  produce_heartbeat(now_ns);
  bring_up_.poll(now_ns);
}

// The end cap's heartbeat comes from the control loop's own cycle (poll), so a
// loop that hangs falls silent on the bus and its drives take their 0x6007 action.
void CanopenMaster::produce_heartbeat(std::int64_t now_ns) {
  if (!producing_heartbeat_ || config_.producer_heartbeat_period_ns <= 0 || now_ns < next_heartbeat_ns_) return;
  if (bus_.send(encode_heartbeat(config_.master_node_id, NmtState::operational)) == CanResult::ok) ++heartbeats_sent_;
  next_heartbeat_ns_ += config_.producer_heartbeat_period_ns;
  // After a stall, one heartbeat now and the period from here, not a burst.
  if (next_heartbeat_ns_ <= now_ns) next_heartbeat_ns_ = now_ns + config_.producer_heartbeat_period_ns;
}

CanResult CanopenMaster::write_target(std::size_t drive_index, double rest_length_m) {
  if (drive_index >= drive_count_) return CanResult::invalid_frame;
  DriveStatus& ds = drives_[drive_index].status;
  const bool finite = std::isfinite(rest_length_m);
  if (!finite) ++targets_refused_;
  const std::uint16_t cw = drives_[drive_index].power.next_controlword(ds.state);
  const bool follow = finite && ds.state == Cia402State::operation_enabled;
  const std::int32_t target = follow ? config_.spool.counts_from_rest_length(rest_length_m) : ds.position_counts;
  ds.controlword_sent = cw;
  ds.target_sent_counts = target;
  return bus_.send(encode_drive_rpdo1(config_.drive_node(drive_index), {cw, target}));
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

CanResult CanopenMaster::send_nmt(NmtCommand command, std::uint8_t id) { return bus_.send(encode_nmt(command, id)); }

bool CanopenMaster::sdo_start(NodeRef node, bool upload, SdoAddress address, std::uint32_t value,
                              std::uint8_t size_bytes, std::int64_t now_ns) {
  if (node.role == NodeRole::load_cell && !config_.use_load_cell) return false;
  CanFrame request;
  SdoClient& client = sdo_client(node);
  const bool started = upload ? client.start_upload(address, now_ns, request)
                              : client.start_download(address, value, size_bytes, now_ns, request);
  if (!started) return false;
  bus_.send(request);
  return true;
}

bool CanopenMaster::sdo_upload(NodeRole node, SdoAddress address, std::int64_t now_ns) {
  return sdo_start(NodeRef{node, 0}, true, address, 0, 0, now_ns);
}

bool CanopenMaster::sdo_download(NodeRole node, SdoAddress address, std::uint32_t value, std::uint8_t size_bytes,
                                 std::int64_t now_ns) {
  return sdo_start(NodeRef{node, 0}, false, address, value, size_bytes, now_ns);
}

}  // namespace tensegrity::fw::canopen
