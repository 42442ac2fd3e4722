// SPDX-License-Identifier: Apache-2.0
#include "core/endcap_controller.hpp"

namespace tensegrity::core {

const char* describe(FaultCause cause) noexcept {
  switch (cause) {
    case FaultCause::none: return "none";
    case FaultCause::over_tension: return "tension above the hard limit";
    case FaultCause::drive_fault: return "motor drive fault";
    case FaultCause::drive_lost: return "motor drive heartbeat lost";
    case FaultCause::sensor_timeout: return "load cell timeout";
    case FaultCause::host_lost: return "host link lost";
    case FaultCause::emergency_stop: return "emergency stop";
    case FaultCause::bad_input: return "control step called with too few motors";
    case FaultCause::node_rebooted: return "CANopen node rebooted";
    case FaultCause::drive_disabled: return "motor drive left operation enabled";
    case FaultCause::stale_position: return "motor drive position stale";
    case FaultCause::loop_stalled: return "control loop stalled";
    case FaultCause::node_not_operational: return "CANopen node left operational";
  }
  return "unknown fault";
}

EndcapController::EndcapController(const EndcapConfig& config) noexcept : config_(config) {
  if (config_.motor_count > kMaxMotorsPerEndcap) config_.motor_count = kMaxMotorsPerEndcap;
  for (auto& motor : motors_) motor.reset(config_.initial_rest_length_m);
}

TableError EndcapController::load(const EndcapTable& table) noexcept {
  const TableError error = validate(table, config_.motor_count, config_.limits);
  if (error != TableError::none) return error;
  if (mode_ == Mode::running && has_active_) {
    pending_ = table;
    has_pending_ = true;
  } else {
    active_ = table;
    clock_ = TableClock(active_);
    has_active_ = true;
    has_pending_ = false;
  }
  return TableError::none;
}

bool EndcapController::start(std::int64_t time_ns) noexcept {
  if (!has_active_ || mode_ == Mode::faulted) return false;
  if (has_pending_) {
    active_ = pending_;
    clock_ = TableClock(active_);
    has_pending_ = false;
  }
  origin_ns_ = time_ns;
  period_index_ = clock_.period_index(0);
  mode_ = Mode::running;
  return true;
}

void EndcapController::stop() noexcept {
  if (mode_ == Mode::running) mode_ = Mode::idle;
}

void EndcapController::trip(FaultCause cause) noexcept {
  if (cause == FaultCause::none) return;
  if (fault_ == FaultCause::none) fault_ = cause;
  mode_ = Mode::faulted;
}

void EndcapController::clear_fault() noexcept {
  fault_ = FaultCause::none;
  if (mode_ == Mode::faulted) mode_ = Mode::idle;
}

void EndcapController::reset_commanded(std::span<const double> rest_length_m) noexcept {
  for (std::uint32_t m = 0; m < config_.motor_count && m < rest_length_m.size(); ++m) {
    motors_[m].reset(rest_length_m[m]);
  }
}

void EndcapController::swap_at_boundary(std::int64_t time_ns, StepStatus& status) noexcept {
  const std::int64_t index = clock_.period_index(time_ns - origin_ns_);
  if (index == period_index_) return;
  period_index_ = index;
  if (!has_pending_) return;
  // The new table's time 0 is the boundary just crossed, so it starts at its first
  // subinterval (shifted by its own phase) whatever its period.
  origin_ns_ += clock_.period_start_ns(index);
  active_ = pending_;
  clock_ = TableClock(active_);
  has_pending_ = false;
  period_index_ = clock_.period_index(time_ns - origin_ns_);
  status.table_swapped = true;
}

StepStatus EndcapController::step(std::int64_t time_ns, double dt_s, std::span<const double> tension_n,
                                  std::span<double> commanded_rest_length_m) noexcept {
  StepStatus status;
  const std::uint32_t n = config_.motor_count;
  if (tension_n.size() < n || commanded_rest_length_m.size() < n) {
    trip(FaultCause::bad_input);
    status.mode = mode_;
    status.fault = fault_;
    return status;
  }
  for (std::uint32_t m = 0; m < n; ++m) {
    if (tension_n[m] > config_.limits.hard_limit_tension_n) trip(FaultCause::over_tension);
  }

  if (mode_ == Mode::running) {
    swap_at_boundary(time_ns, status);
    const std::int64_t t = time_ns - origin_ns_;
    const std::uint32_t j = clock_.subinterval(t);
    status.subinterval = j;
    for (std::uint32_t m = 0; m < n; ++m) {
      const std::uint8_t flags = motors_[m].step(active_.rest_length_m[m][j], tension_n[m], dt_s, config_.limits);
      if (flags & kMotorCutOff) status.cutoff_mask |= static_cast<std::uint8_t>(1U << m);
      if (flags & kMotorRateLimited) {
        status.rate_limited_mask |= static_cast<std::uint8_t>(1U << m);
      }
    }
  }
  // Idle and faulted both hold: the commanded length stays where it is.
  for (std::uint32_t m = 0; m < n; ++m) commanded_rest_length_m[m] = motors_[m].commanded_m();
  status.mode = mode_;
  status.fault = fault_;
  return status;
}

}  // namespace tensegrity::core
