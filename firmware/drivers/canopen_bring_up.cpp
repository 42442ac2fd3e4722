// SPDX-License-Identifier: Apache-2.0
#include "firmware/drivers/canopen_bring_up.hpp"

#include <array>
#include <cstdio>

#include "firmware/drivers/canopen_master.hpp"
#include "firmware/drivers/sdo_abort.hpp"

namespace tensegrity::fw::canopen {

void CanopenBringUp::start(std::int64_t now_ns) {
  step_ = BringUpStep::idle;
  step_started_ns_ = 0;
  request_sent_ = false;
  drive_index_ = 0;
  failure_ = {};
  m_.request_power(PowerRequest::disabled);
  // Reset communication makes every node announce itself with a boot-up message,
  // also when it was left operational by an earlier run of the firmware.
  for (std::size_t i = 0; i < m_.drive_count_; ++i)
    m_.send_nmt(NmtCommand::reset_communication, m_.config_.drive_node(i));
  if (m_.config_.use_load_cell) m_.send_nmt(NmtCommand::reset_communication, m_.config_.load_cell_node_id);
  // The end cap's heartbeat starts now: the drives are told to watch it below, and
  // monitoring on their side starts with the first one they hear after that.
  if (!m_.producing_heartbeat_) {
    m_.producing_heartbeat_ = true;
    m_.next_heartbeat_ns_ = now_ns;
  }
  enter_step(BringUpStep::wait_boot, now_ns);
}

void CanopenBringUp::enter_step(BringUpStep step, std::int64_t now_ns) {
  step_ = step;
  step_started_ns_ = now_ns;
  request_sent_ = false;
  drive_index_ = 0;
  if (step == BringUpStep::done) m_.emit(MasterEventKind::bring_up_done, m_.config_.drive_node_id, now_ns);
}

void CanopenBringUp::fail(const char* what, std::int64_t now_ns, std::uint32_t abort_code) {
  // With several drives the text names the one that failed (drive node id).
  char where[48];
  const BringUpStep step = step_;
  const bool per_drive = step == BringUpStep::set_mode || step == BringUpStep::check_mode ||
                         step == BringUpStep::set_cycle_period || step == BringUpStep::set_interpolation_value ||
                         step == BringUpStep::set_interpolation_index || step == BringUpStep::set_heartbeat_consumer ||
                         step == BringUpStep::set_abort_connection || step == BringUpStep::enable;
  if (step == BringUpStep::set_heartbeat_producer) {  // every node, the load cell last
    const bool drive = drive_index_ < m_.drive_count_;
    std::snprintf(where, sizeof where, "%s (%s %u)", to_string(step), drive ? "drive" : "load cell",
                  static_cast<unsigned>(drive ? m_.config_.drive_node(drive_index_) : m_.config_.load_cell_node_id));
  } else if (m_.drive_count_ > 1 && per_drive) {
    std::snprintf(where, sizeof where, "%s (drive %u)", to_string(step_),
                  static_cast<unsigned>(m_.config_.drive_node(drive_index_)));
  } else {
    std::snprintf(where, sizeof where, "%s", to_string(step_));
  }
  if (abort_code != 0) {
    std::snprintf(failure_.data(), failure_.size(), "%s: %s: SDO abort 0x%08X (%s)", where, what,
                  static_cast<unsigned>(abort_code), sdo_abort::text(abort_code));
  } else {
    std::snprintf(failure_.data(), failure_.size(), "%s: %s", where, what);
  }
  step_ = BringUpStep::failed;
  m_.emit(MasterEventKind::bring_up_failed, m_.config_.drive_node_id, now_ns);
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
constexpr std::array<SdoStepSpec, 7> kSdoSteps{{
    {BringUpStep::set_mode, false, {kOdModesOfOperation, 0}, 1, "writing 0x6060"},
    {BringUpStep::check_mode, true, {kOdModesOfOperationDisplay, 0}, 0, "reading 0x6061"},
    {BringUpStep::set_cycle_period, false, {kOdCommunicationCyclePeriod, 0}, 4, "writing 0x1006"},
    {BringUpStep::set_interpolation_value, false, {kOdInterpolationTimePeriod, 1}, 1, "writing 0x60C2 sub 1"},
    {BringUpStep::set_interpolation_index, false, {kOdInterpolationTimePeriod, 2}, 1, "writing 0x60C2 sub 2"},
    {BringUpStep::set_heartbeat_consumer, false, {kOdConsumerHeartbeatTime, 1}, 4, "writing 0x1016 sub 1"},
    {BringUpStep::set_abort_connection, false, {kOdAbortConnectionOption, 0}, 2, "writing 0x6007"},
}};
}  // namespace

// One SDO step for drive drive_index_: starts the transfer once, then
// waits for its outcome. True when it finished: `next` is the step to go on with
// (failed: fail_bring_up was called).
bool CanopenBringUp::step_drive_sdo(std::int64_t now_ns, BringUpStep& next) {
  const SdoStepSpec* spec = nullptr;
  for (const SdoStepSpec& s : kSdoSteps) {
    if (s.step == step_) spec = &s;
  }
  if (spec == nullptr) return false;
  // Each drive watches the end cap's heartbeat and stops its motor by itself when
  // the end cap falls silent (dead computer, hung loop).
  const bool supervised = m_.config_.drive_consumer_heartbeat_ms > 0 && m_.config_.producer_heartbeat_period_ns > 0;
  std::uint32_t value = 0;
  // The config checked that 0x60C2 can say the period (app/config.cpp).
  const InterpolationPeriod interpolation =
      interpolation_period(m_.config_.sync_period_ns).value_or(InterpolationPeriod{});
  switch (step_) {
    case BringUpStep::set_mode: value = kModeCyclicSynchronousPosition; break;
    case BringUpStep::set_cycle_period: value = static_cast<std::uint32_t>(m_.config_.sync_period_ns / 1'000); break;
    case BringUpStep::set_interpolation_value: value = interpolation.value; break;
    case BringUpStep::set_interpolation_index: value = static_cast<std::uint8_t>(interpolation.index); break;
    case BringUpStep::set_heartbeat_consumer:
      value = consumer_heartbeat_entry(m_.config_.master_node_id, m_.config_.drive_consumer_heartbeat_ms);
      break;
    case BringUpStep::set_abort_connection:
      value = static_cast<std::uint16_t>(m_.config_.drive_abort_connection);
      break;
    default: break;
  }
  SdoClient& sdo = m_.drives_[drive_index_].sdo;
  if (!request_sent_) {
    request_sent_ = m_.sdo_start(CanopenMaster::NodeRef{NodeRole::drive, drive_index_}, spec->upload, spec->address,
                                 value, spec->size_bytes, now_ns);
    return false;
  }
  if (sdo.transfer().status == SdoStatus::pending) return false;
  const SdoTransfer done = sdo.transfer();
  sdo.acknowledge();
  next = BringUpStep::failed;
  if (done.status != SdoStatus::done) {
    fail(spec->what, now_ns, done.abort_code);
    return true;
  }
  switch (step_) {
    case BringUpStep::set_mode: next = BringUpStep::check_mode; break;
    case BringUpStep::check_mode:
      if (static_cast<std::int8_t>(done.value & 0xFFU) != kModeCyclicSynchronousPosition) {
        fail("drive does not report mode 8 (cyclic synchronous position)", now_ns);
        return true;
      }
      next = BringUpStep::set_cycle_period;
      break;
    case BringUpStep::set_cycle_period: next = BringUpStep::set_interpolation_value; break;
    case BringUpStep::set_interpolation_value: next = BringUpStep::set_interpolation_index; break;
    case BringUpStep::set_interpolation_index:
      next = supervised ? BringUpStep::set_heartbeat_consumer : BringUpStep::start_nodes;
      break;
    case BringUpStep::set_heartbeat_consumer: next = BringUpStep::set_abort_connection; break;
    default: next = BringUpStep::start_nodes; break;
  }
  return true;
}

// 0x1017 of node drive_index_ (the load cell after the drives): starts the
// write once, then waits for its outcome. True when every node is done or bring-up
// failed. The node's heartbeat follows the new period from its next beat, so the
// consumer's timeouts hold whatever the device's factory default was.
bool CanopenBringUp::step_producer_sdo(std::int64_t now_ns) {
  const std::size_t nodes = m_.drive_count_ + (m_.config_.use_load_cell ? 1 : 0);
  if (m_.config_.node_heartbeat_period_ms == 0 || drive_index_ >= nodes) {
    enter_step(BringUpStep::set_mode, now_ns);
    return true;
  }
  const CanopenMaster::NodeRef node = drive_index_ < m_.drive_count_
                                          ? CanopenMaster::NodeRef{NodeRole::drive, drive_index_}
                                          : CanopenMaster::NodeRef{NodeRole::load_cell, 0};
  SdoClient& sdo = m_.sdo_client(node);
  if (!request_sent_) {
    request_sent_ =
        m_.sdo_start(node, false, {kOdProducerHeartbeatTime, 0}, m_.config_.node_heartbeat_period_ms, 2, now_ns);
    return false;
  }
  if (sdo.transfer().status == SdoStatus::pending) return false;
  const SdoTransfer done = sdo.transfer();
  sdo.acknowledge();
  if (done.status != SdoStatus::done) {
    fail("writing 0x1017", now_ns, done.abort_code);
    return true;
  }
  const std::size_t following = drive_index_ + 1;
  enter_step(BringUpStep::set_heartbeat_producer, now_ns);
  drive_index_ = following;
  return step_producer_sdo(now_ns);
}

void CanopenBringUp::poll(std::int64_t now_ns) {
  if (step_ == BringUpStep::idle || step_ == BringUpStep::done || step_ == BringUpStep::failed) return;

  const auto heard_since_step = [&](const HeartbeatMonitor& hb) {
    return hb.status().alive && hb.status().last_seen_ns >= step_started_ns_;
  };
  const auto operational = [](const HeartbeatMonitor& hb) {
    return hb.status().alive && hb.status().state == NmtState::operational;
  };
  // Next drive within the same step, or the next step after the last drive.
  const auto next_drive_or = [&](BringUpStep next) {
    if (drive_index_ + 1 < m_.drive_count_) {
      const std::size_t following = drive_index_ + 1;
      enter_step(step_, now_ns);
      drive_index_ = following;
    } else {
      enter_step(next, now_ns);
    }
  };
  const auto all_drives = [&](auto&& predicate) {
    for (std::size_t i = 0; i < m_.drive_count_; ++i) {
      if (!predicate(i)) return false;
    }
    return true;
  };

  switch (step_) {
    case BringUpStep::wait_boot:
      if (all_drives([&](std::size_t i) { return heard_since_step(m_.drives_[i].hb); }) &&
          (!m_.config_.use_load_cell || heard_since_step(m_.load_cell_hb_))) {
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
    case BringUpStep::set_cycle_period:
    case BringUpStep::set_interpolation_value:
    case BringUpStep::set_interpolation_index:
    case BringUpStep::set_heartbeat_consumer:
    case BringUpStep::set_abort_connection: {
      BringUpStep next = BringUpStep::idle;
      if (!step_drive_sdo(now_ns, next)) break;  // still waiting for the answer
      if (next != BringUpStep::failed) next_drive_or(next);
      return;
    }
    case BringUpStep::start_nodes:
      if (!request_sent_) {
        for (std::size_t i = 0; i < m_.drive_count_; ++i) m_.send_nmt(NmtCommand::start, m_.config_.drive_node(i));
        if (m_.config_.use_load_cell) m_.send_nmt(NmtCommand::start, m_.config_.load_cell_node_id);
        request_sent_ = true;
      } else if (all_drives([&](std::size_t i) { return operational(m_.drives_[i].hb); }) &&
                 (!m_.config_.use_load_cell || operational(m_.load_cell_hb_))) {
        m_.request_power(PowerRequest::operation_enabled);
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
bool CanopenBringUp::step_enable(std::int64_t now_ns) {
  bool all_enabled = true;
  for (std::size_t i = 0; i < m_.drive_count_; ++i) {
    const Cia402State state = m_.drives_[i].status.state;
    if (state == Cia402State::fault || state == Cia402State::fault_reaction_active) {
      m_.request_power(PowerRequest::disabled);
      drive_index_ = i;
      fail("drive entered fault", now_ns);
      return true;
    }
    all_enabled = all_enabled && state == Cia402State::operation_enabled;
  }
  const bool done = all_enabled || m_.power_request() != PowerRequest::operation_enabled;
  if (done) enter_step(BringUpStep::done, now_ns);
  return done;
}

void CanopenBringUp::fail_step_after_timeout(std::int64_t now_ns) {
  if (now_ns - step_started_ns_ <= m_.config_.bring_up_step_timeout_ns) return;
  m_.request_power(PowerRequest::disabled);
  if (step_ == BringUpStep::enable) {  // name the first drive that did not come up
    while (drive_index_ + 1 < m_.drive_count_ &&
           m_.drives_[drive_index_].status.state == Cia402State::operation_enabled) {
      ++drive_index_;
    }
  }
  fail(step_ == BringUpStep::wait_boot ? "no heartbeat from a node (timeout)" : "timeout", now_ns);
}

}  // namespace tensegrity::fw::canopen
