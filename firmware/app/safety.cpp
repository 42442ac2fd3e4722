// SPDX-License-Identifier: Apache-2.0
#include "firmware/app/safety.hpp"

namespace tensegrity::fw::app {

using canopen::Cia402State;
using canopen::MasterEventKind;
using core::FaultCause;

bool SafetyMonitor::is_drive(std::uint8_t node_id, const canopen::CanopenMaster& master) const {
  for (std::size_t i = 0; i < master.drive_count(); ++i) {
    if (master.config().drive_node(i) == node_id) return true;
  }
  return false;
}

FaultCause SafetyMonitor::on_event(const canopen::MasterEvent& e, const canopen::CanopenMaster& master) {
  const bool drive = is_drive(e.node_id, master);
  switch (e.kind) {
    case MasterEventKind::emcy:
      // Error code 0 is "error reset / no error": a node announcing recovery.
      if (drive && e.emcy.error_code != 0) return FaultCause::drive_fault;
      if (!drive && e.emcy.error_code != 0) return FaultCause::sensor_timeout;
      return FaultCause::none;
    case MasterEventKind::drive_fault: return FaultCause::drive_fault;
    case MasterEventKind::heartbeat_lost: return drive ? FaultCause::drive_lost : FaultCause::sensor_timeout;
    // Bring-up resets every node and expects their boot-ups; once it is done a
    // boot-up means the node lost power or reset itself: pre-operational, unpowered.
    case MasterEventKind::boot_up:
      return master.bring_up_step() == canopen::BringUpStep::done ? FaultCause::node_rebooted : FaultCause::none;
    default: return FaultCause::none;
  }
}

FaultCause SafetyMonitor::check(const canopen::CanopenMaster& master, std::int64_t now_ns, bool armed) {
  // Freshness is tracked also while disarmed so arming does not trip on a stale clock.
  const canopen::LoadCellStatus& lc = master.load_cell();
  const bool new_sample = lc.seen && (!sequence_seen_ || lc.sequence != last_sequence_);
  if (new_sample) {
    sequence_seen_ = true;
    last_sequence_ = lc.sequence;
    for (std::uint32_t ch = 0; ch < 2; ++ch) {
      if (lc.valid[ch]) fresh_ns_[ch] = now_ns;
    }
  }
  if (armed && !was_armed_) {
    // The sample timeout runs from arming at the earliest.
    for (std::int64_t& t : fresh_ns_) t = t > now_ns ? t : now_ns;
    armed_ns_ = now_ns;
  }
  was_armed_ = armed;
  if (!armed) return FaultCause::none;

  const bool resetting = now_ns < reset_until_ns_;
  for (std::size_t i = 0; i < master.drive_count() && !resetting; ++i) {
    const Cia402State s = master.drive(i).state;
    if (s == Cia402State::fault || s == Cia402State::fault_reaction_active) return FaultCause::drive_fault;
  }
  for (std::size_t i = 0; i < master.drive_count(); ++i) {
    if (!master.drive_heartbeat(i).alive) return FaultCause::drive_lost;
  }
  // A node that left operational (its heartbeat says pre-operational or stopped)
  // takes no RPDO and sends no TPDO: its drive holds a target the end cap can no
  // longer move or watch. Its heartbeat carries the state, so this is seen within
  // one of its producer periods, before any position or sample timeout.
  for (std::size_t i = 0; i < master.drive_count(); ++i) {
    if (master.drive_heartbeat(i).state != canopen::NmtState::operational) return FaultCause::node_not_operational;
  }
  if (config_.use_load_cell && master.heartbeat(canopen::NodeRole::load_cell).alive &&
      master.heartbeat(canopen::NodeRole::load_cell).state != canopen::NmtState::operational) {
    return FaultCause::node_not_operational;
  }
  // Every drive is checked for the faults that quick-stop before any for a milder
  // one: a stale position latched on one drive must not hide another leaving
  // operation enabled, which would otherwise be stepped back up unseen.
  const bool enable_wanted = master.power_request() == canopen::PowerRequest::operation_enabled && !resetting;
  for (std::size_t i = 0; i < master.drive_count(); ++i) {
    if (enable_wanted && master.drive(i).state != Cia402State::operation_enabled) return FaultCause::drive_disabled;
  }
  for (std::size_t i = 0; i < master.drive_count(); ++i) {
    const canopen::DriveStatus& d = master.drive(i);
    const std::int64_t since = d.position_updated_ns > armed_ns_ ? d.position_updated_ns : armed_ns_;
    if (now_ns - since > config_.drive_position_timeout_ns) return FaultCause::stale_position;
  }
  if (config_.use_load_cell) {
    if (!master.heartbeat(canopen::NodeRole::load_cell).alive) return FaultCause::sensor_timeout;
    for (std::uint32_t ch = 0; ch < config_.motor_count && ch < 2; ++ch) {
      if (now_ns - fresh_ns_[ch] > config_.load_cell_sample_timeout_ns) return FaultCause::sensor_timeout;
    }
  }
  return FaultCause::none;
}

}  // namespace tensegrity::fw::app
