// SPDX-License-Identifier: Apache-2.0
// CanopenMaster's start-up sequence, one step per poll() so the control loop
// keeps its period while the nodes come up.
#include <array>
#include <cstdio>

#include "firmware/drivers/canopen_master.hpp"
#include "firmware/drivers/sdo_abort.hpp"

namespace tensegrity::fw::canopen {

void CanopenMaster::start_bring_up(std::int64_t now_ns) {
  bring_up_ = BringUp{};
  request_power(PowerRequest::disabled);
  // Reset communication makes every node announce itself with a boot-up message,
  // also when it was left operational by an earlier run of the firmware.
  for (std::size_t i = 0; i < drive_count_; ++i) send_nmt(NmtCommand::reset_communication, config_.drive_node(i));
  if (config_.use_load_cell) send_nmt(NmtCommand::reset_communication, config_.load_cell_node_id);
  // The end cap's heartbeat starts now: the drives are told to watch it below, and
  // monitoring on their side starts with the first one they hear after that.
  if (!producing_heartbeat_) {
    producing_heartbeat_ = true;
    next_heartbeat_ns_ = now_ns;
  }
  enter_step(BringUpStep::wait_boot, now_ns);
}

void CanopenMaster::enter_step(BringUpStep step, std::int64_t now_ns) {
  bring_up_.step = step;
  bring_up_.step_started_ns = now_ns;
  bring_up_.request_sent = false;
  bring_up_.drive_index = 0;
  if (step == BringUpStep::done) emit(MasterEventKind::bring_up_done, config_.drive_node_id, now_ns);
}

void CanopenMaster::fail_bring_up(const char* what, std::int64_t now_ns, std::uint32_t abort_code) {
  // With several drives the text names the one that failed (drive node id).
  char where[48];
  const BringUpStep step = bring_up_.step;
  const bool per_drive = step == BringUpStep::set_mode || step == BringUpStep::check_mode ||
                         step == BringUpStep::set_heartbeat_consumer || step == BringUpStep::set_abort_connection ||
                         step == BringUpStep::enable;
  if (step == BringUpStep::set_heartbeat_producer) {  // every node, the load cell last
    const bool drive = bring_up_.drive_index < drive_count_;
    std::snprintf(where, sizeof where, "%s (%s %u)", to_string(step), drive ? "drive" : "load cell",
                  static_cast<unsigned>(drive ? config_.drive_node(bring_up_.drive_index) : config_.load_cell_node_id));
  } else if (drive_count_ > 1 && per_drive) {
    std::snprintf(where, sizeof where, "%s (drive %u)", to_string(bring_up_.step),
                  static_cast<unsigned>(config_.drive_node(bring_up_.drive_index)));
  } else {
    std::snprintf(where, sizeof where, "%s", to_string(bring_up_.step));
  }
  if (abort_code != 0) {
    std::snprintf(bring_up_.failure.data(), bring_up_.failure.size(), "%s: %s: SDO abort 0x%08X (%s)", where, what,
                  static_cast<unsigned>(abort_code), sdo_abort::text(abort_code));
  } else {
    std::snprintf(bring_up_.failure.data(), bring_up_.failure.size(), "%s: %s", where, what);
  }
  bring_up_.step = BringUpStep::failed;
  emit(MasterEventKind::bring_up_failed, config_.drive_node_id, now_ns);
}

namespace {
// The per-drive SDO steps of bring-up, in order: what each writes or reads.
struct SdoStepSpec {
  BringUpStep step;
  bool upload;
  SdoAddress address;
  std::uint8_t size_bytes;
  const char* what;  // for the failure text
};
constexpr std::array<SdoStepSpec, 4> kSdoSteps{{
    {BringUpStep::set_mode, false, {kOdModesOfOperation, 0}, 1, "writing 0x6060"},
    {BringUpStep::check_mode, true, {kOdModesOfOperationDisplay, 0}, 0, "reading 0x6061"},
    {BringUpStep::set_heartbeat_consumer, false, {kOdConsumerHeartbeatTime, 1}, 4, "writing 0x1016 sub 1"},
    {BringUpStep::set_abort_connection, false, {kOdAbortConnectionOption, 0}, 2, "writing 0x6007"},
}};
}  // namespace

// One SDO step for drive bring_up_.drive_index: starts the transfer once, then
// waits for its outcome. True when it finished: `next` is the step to go on with
// (failed: fail_bring_up was called).
bool CanopenMaster::step_drive_sdo(std::int64_t now_ns, BringUpStep& next) {
  BringUp& b = bring_up_;
  const SdoStepSpec* spec = nullptr;
  for (const SdoStepSpec& s : kSdoSteps) {
    if (s.step == b.step) spec = &s;
  }
  if (spec == nullptr) return false;
  // Each drive watches the end cap's heartbeat and stops its motor by itself when
  // the end cap falls silent (dead computer, hung loop).
  const bool supervised = config_.drive_consumer_heartbeat_ms > 0 && config_.producer_heartbeat_period_ns > 0;
  std::uint32_t value = 0;
  switch (b.step) {
    case BringUpStep::set_mode: value = kModeCyclicSynchronousPosition; break;
    case BringUpStep::set_heartbeat_consumer:
      value = consumer_heartbeat_entry(config_.master_node_id, config_.drive_consumer_heartbeat_ms);
      break;
    case BringUpStep::set_abort_connection: value = static_cast<std::uint16_t>(config_.drive_abort_connection); break;
    default: break;
  }
  SdoClient& sdo = drives_[b.drive_index].sdo;
  if (!b.request_sent) {
    b.request_sent = sdo_start(NodeRef{NodeRole::drive, b.drive_index}, spec->upload, spec->address, value,
                               spec->size_bytes, now_ns);
    return false;
  }
  if (sdo.transfer().status == SdoStatus::pending) return false;
  const SdoTransfer done = sdo.transfer();
  sdo.acknowledge();
  next = BringUpStep::failed;
  if (done.status != SdoStatus::done) {
    fail_bring_up(spec->what, now_ns, done.abort_code);
    return true;
  }
  switch (b.step) {
    case BringUpStep::set_mode: next = BringUpStep::check_mode; break;
    case BringUpStep::check_mode:
      if (static_cast<std::int8_t>(done.value & 0xFFU) != kModeCyclicSynchronousPosition) {
        fail_bring_up("drive does not report mode 8 (cyclic synchronous position)", now_ns);
        return true;
      }
      next = supervised ? BringUpStep::set_heartbeat_consumer : BringUpStep::start_nodes;
      break;
    case BringUpStep::set_heartbeat_consumer: next = BringUpStep::set_abort_connection; break;
    default: next = BringUpStep::start_nodes; break;
  }
  return true;
}

// 0x1017 of node bring_up_.drive_index (the load cell after the drives): starts the
// write once, then waits for its outcome. True when every node is done or bring-up
// failed. The node's heartbeat follows the new period from its next beat, so the
// consumer's timeouts hold whatever the device's factory default was.
bool CanopenMaster::step_producer_sdo(std::int64_t now_ns) {
  BringUp& b = bring_up_;
  const std::size_t nodes = drive_count_ + (config_.use_load_cell ? 1 : 0);
  if (config_.node_heartbeat_period_ms == 0 || b.drive_index >= nodes) {
    enter_step(BringUpStep::set_mode, now_ns);
    return true;
  }
  const NodeRef node =
      b.drive_index < drive_count_ ? NodeRef{NodeRole::drive, b.drive_index} : NodeRef{NodeRole::load_cell, 0};
  SdoClient& sdo = sdo_client(node);
  if (!b.request_sent) {
    b.request_sent = sdo_start(node, false, {kOdProducerHeartbeatTime, 0}, config_.node_heartbeat_period_ms, 2, now_ns);
    return false;
  }
  if (sdo.transfer().status == SdoStatus::pending) return false;
  const SdoTransfer done = sdo.transfer();
  sdo.acknowledge();
  if (done.status != SdoStatus::done) {
    fail_bring_up("writing 0x1017", now_ns, done.abort_code);
    return true;
  }
  const std::size_t following = b.drive_index + 1;
  enter_step(BringUpStep::set_heartbeat_producer, now_ns);
  b.drive_index = following;
  return step_producer_sdo(now_ns);
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
  // Next drive within the same step, or the next step after the last drive.
  const auto next_drive_or = [&](BringUpStep next) {
    if (b.drive_index + 1 < drive_count_) {
      const std::size_t following = b.drive_index + 1;
      enter_step(b.step, now_ns);
      b.drive_index = following;
    } else {
      enter_step(next, now_ns);
    }
  };
  const auto all_drives = [&](auto&& predicate) {
    for (std::size_t i = 0; i < drive_count_; ++i) {
      if (!predicate(i)) return false;
    }
    return true;
  };

  switch (b.step) {
    case BringUpStep::wait_boot:
      if (all_drives([&](std::size_t i) { return heard_since_step(drives_[i].hb); }) &&
          (!config_.use_load_cell || heard_since_step(load_cell_hb_))) {
        enter_step(BringUpStep::set_heartbeat_producer, now_ns);
        step_producer_sdo(now_ns);
        return;
      }
      break;
    case BringUpStep::set_heartbeat_producer:
      if (step_producer_sdo(now_ns)) return;
      break;
    case BringUpStep::set_mode:
    case BringUpStep::check_mode:
    case BringUpStep::set_heartbeat_consumer:
    case BringUpStep::set_abort_connection: {
      BringUpStep next = BringUpStep::idle;
      if (!step_drive_sdo(now_ns, next)) break;  // still waiting for the answer
      if (next != BringUpStep::failed) next_drive_or(next);
      return;
    }
    case BringUpStep::start_nodes:
      if (!b.request_sent) {
        for (std::size_t i = 0; i < drive_count_; ++i) send_nmt(NmtCommand::start, config_.drive_node(i));
        if (config_.use_load_cell) send_nmt(NmtCommand::start, config_.load_cell_node_id);
        b.request_sent = true;
      } else if (all_drives([&](std::size_t i) { return operational(drives_[i].hb); }) &&
                 (!config_.use_load_cell || operational(load_cell_hb_))) {
        request_power(PowerRequest::operation_enabled);
        enter_step(BringUpStep::enable, now_ns);
        return;
      }
      break;
    case BringUpStep::enable:
      if (step_enable(now_ns)) return;
      break;
    default: return;
  }
  fail_step_after_timeout(now_ns);
}

// True when the enable step ended: every drive operation enabled, one in fault, or
// the end cap asked for a stop meanwhile (its stop outlasts the bring-up: the nodes
// are up and the drives stay stopped until it asks for them again).
bool CanopenMaster::step_enable(std::int64_t now_ns) {
  BringUp& b = bring_up_;
  bool all_enabled = true;
  for (std::size_t i = 0; i < drive_count_; ++i) {
    const Cia402State state = drives_[i].status.state;
    if (state == Cia402State::fault || state == Cia402State::fault_reaction_active) {
      request_power(PowerRequest::disabled);
      b.drive_index = i;
      fail_bring_up("drive entered fault", now_ns);
      return true;
    }
    all_enabled = all_enabled && state == Cia402State::operation_enabled;
  }
  const bool done = all_enabled || power_request() != PowerRequest::operation_enabled;
  if (done) enter_step(BringUpStep::done, now_ns);
  return done;
}

void CanopenMaster::fail_step_after_timeout(std::int64_t now_ns) {
  BringUp& b = bring_up_;
  if (now_ns - b.step_started_ns <= config_.bring_up_step_timeout_ns) return;
  request_power(PowerRequest::disabled);
  if (b.step == BringUpStep::enable) {  // name the first drive that did not come up
    while (b.drive_index + 1 < drive_count_ && drives_[b.drive_index].status.state == Cia402State::operation_enabled) {
      ++b.drive_index;
    }
  }
  fail_bring_up(b.step == BringUpStep::wait_boot ? "no heartbeat from a node (timeout)" : "timeout", now_ns);
}

}  // namespace tensegrity::fw::canopen
