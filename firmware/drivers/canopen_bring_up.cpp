// SPDX-License-Identifier: Apache-2.0
// CanopenMaster's start-up sequence, one step per poll() so the control loop
// keeps its period while the nodes come up.
#include <cstdio>

#include "firmware/drivers/canopen_master.hpp"
#include "firmware/drivers/sdo_abort.hpp"

namespace tensegrity::fw::canopen {

void CanopenMaster::start_bring_up(std::int64_t now_ns) {
  bring_up_ = BringUp{};
  power_.request(PowerRequest::disabled);
  // Reset communication makes every node announce itself with a boot-up message,
  // also when it was left operational by an earlier run of the firmware.
  send_nmt(NmtCommand::reset_communication, config_.drive_node_id);
  if (config_.use_load_cell) send_nmt(NmtCommand::reset_communication, config_.load_cell_node_id);
  enter_step(BringUpStep::wait_boot, now_ns);
}

void CanopenMaster::enter_step(BringUpStep step, std::int64_t now_ns) {
  bring_up_.step = step;
  bring_up_.step_started_ns = now_ns;
  bring_up_.request_sent = false;
  if (step == BringUpStep::done) emit(MasterEventKind::bring_up_done, config_.drive_node_id, now_ns);
}

void CanopenMaster::fail_bring_up(const char* what, std::int64_t now_ns, std::uint32_t abort_code) {
  if (abort_code != 0) {
    std::snprintf(bring_up_.failure.data(), bring_up_.failure.size(), "%s: %s: SDO abort 0x%08X (%s)",
                  to_string(bring_up_.step), what, static_cast<unsigned>(abort_code), sdo_abort::text(abort_code));
  } else {
    std::snprintf(bring_up_.failure.data(), bring_up_.failure.size(), "%s: %s", to_string(bring_up_.step), what);
  }
  bring_up_.step = BringUpStep::failed;
  emit(MasterEventKind::bring_up_failed, config_.drive_node_id, now_ns);
}

void CanopenMaster::step_bring_up(std::int64_t now_ns) {
  BringUp& b = bring_up_;
  if (b.step == BringUpStep::idle || b.step == BringUpStep::done || b.step == BringUpStep::failed) return;

  const auto heard_since_step = [&](const HeartbeatMonitor& hb) {
    return hb.status().alive && hb.status().last_seen_ns >= b.step_started_ns;
  };
  const auto operational = [](const HeartbeatMonitor& hb) {
    return hb.status().alive && hb.status().state == NmtState::operational;
  };
  // An SDO step: start the transfer once, then wait for its outcome.
  const auto sdo_step = [&](bool upload, std::uint16_t index, std::uint32_t value) -> const SdoTransfer* {
    if (!b.request_sent) {
      b.request_sent = upload ? sdo_upload(NodeRole::drive, {index, 0}, now_ns)
                              : sdo_download(NodeRole::drive, {index, 0}, value, 1, now_ns);
      return nullptr;
    }
    const SdoTransfer& t = drive_sdo_.transfer();
    return t.status == SdoStatus::pending ? nullptr : &t;
  };

  switch (b.step) {
    case BringUpStep::wait_boot:
      if (heard_since_step(drive_hb_) && (!config_.use_load_cell || heard_since_step(load_cell_hb_))) {
        enter_step(BringUpStep::set_mode, now_ns);
        return;
      }
      break;
    case BringUpStep::set_mode:
      if (const SdoTransfer* t = sdo_step(false, kOdModesOfOperation, kModeCyclicSynchronousPosition)) {
        const SdoTransfer done = *t;
        drive_sdo_.acknowledge();
        if (done.status != SdoStatus::done) return fail_bring_up("writing 0x6060", now_ns, done.abort_code);
        enter_step(BringUpStep::check_mode, now_ns);
        return;
      }
      break;
    case BringUpStep::check_mode:
      if (const SdoTransfer* t = sdo_step(true, kOdModesOfOperationDisplay, 0)) {
        const SdoTransfer done = *t;
        drive_sdo_.acknowledge();
        if (done.status != SdoStatus::done) return fail_bring_up("reading 0x6061", now_ns, done.abort_code);
        if (static_cast<std::int8_t>(done.value & 0xFFU) != kModeCyclicSynchronousPosition) {
          return fail_bring_up("drive does not report mode 8 (cyclic synchronous position)", now_ns);
        }
        enter_step(BringUpStep::start_nodes, now_ns);
        return;
      }
      break;
    case BringUpStep::start_nodes:
      if (!b.request_sent) {
        send_nmt(NmtCommand::start, config_.drive_node_id);
        if (config_.use_load_cell) send_nmt(NmtCommand::start, config_.load_cell_node_id);
        b.request_sent = true;
      } else if (operational(drive_hb_) && (!config_.use_load_cell || operational(load_cell_hb_))) {
        power_.request(PowerRequest::operation_enabled);
        enter_step(BringUpStep::enable, now_ns);
        return;
      }
      break;
    case BringUpStep::enable:
      if (drive_.state == Cia402State::operation_enabled) {
        enter_step(BringUpStep::done, now_ns);
        return;
      }
      if (drive_.state == Cia402State::fault || drive_.state == Cia402State::fault_reaction_active) {
        power_.request(PowerRequest::disabled);
        return fail_bring_up("drive entered fault", now_ns);
      }
      break;
    default:
      return;
  }
  if (now_ns - b.step_started_ns > config_.bring_up_step_timeout_ns) {
    power_.request(PowerRequest::disabled);
    fail_bring_up(b.step == BringUpStep::wait_boot ? "no heartbeat from a node (timeout)" : "timeout", now_ns);
  }
}

}  // namespace tensegrity::fw::canopen
