// SPDX-License-Identifier: Apache-2.0
#pragma once
// The hardware-free heart of one end cap: plays its periodic table through one motor
// loop per motor, guards tensions, latches faults, and swaps a newly loaded table in
// at a period boundary. Used unchanged by the firmware, the HIL and the simulator.
// No heap after construction, no exceptions, no OS/DDS/CAN dependency.
#include <array>
#include <cstdint>
#include <span>

#include "core/fault.hpp"
#include "core/limits.hpp"
#include "core/motor_loop.hpp"
#include "core/table.hpp"

namespace tensegrity::core {

struct EndcapConfig {
  std::uint32_t motor_count = 2;
  MotorLimits limits{};
  double initial_rest_length_m = 0.95;
};

enum class Mode : std::uint8_t { idle = 0, running, faulted };

struct StepStatus {
  Mode mode = Mode::idle;
  FaultCause fault = FaultCause::none;
  std::uint32_t subinterval = 0;
  std::uint8_t cutoff_mask = 0;  // bit m: motor m's shortening was cut off
  std::uint8_t rate_limited_mask = 0;
  bool table_swapped = false;  // a pending table became active this cycle
};

class EndcapController {
 public:
  explicit EndcapController(const EndcapConfig& config) noexcept;

  const EndcapConfig& config() const noexcept { return config_; }

  // Validates and accepts a table. Idle: it becomes active at once. Running: it is
  // kept pending and swapped in at the active table's next period boundary, never
  // mid-period. A rejected table changes nothing.
  TableError load(const EndcapTable& table) noexcept;
  bool has_table() const noexcept { return has_active_; }
  bool has_pending_table() const noexcept { return has_pending_; }
  const EndcapTable& active_table() const noexcept { return active_; }

  // Starts playing the active table with table time 0 at caller time `time_ns`.
  // Returns false (and stays idle) without a table or while faulted.
  bool start(std::int64_t time_ns) noexcept;
  void stop() noexcept;

  // Latches a fault (motors hold) until clear_fault(); the first cause is kept.
  void trip(FaultCause cause) noexcept;
  // Clears a latched fault; the end cap returns to idle and must be started again.
  void clear_fault() noexcept;
  FaultCause fault() const noexcept { return fault_; }
  Mode mode() const noexcept { return mode_; }

  // Sets the commanded rest lengths, e.g. from the drive's actual position at boot.
  void reset_commanded(std::span<const double> rest_length_m) noexcept;

  // One control cycle at caller time `time_ns`, `dt_s` after the previous one.
  // Reads one tension per motor, writes one commanded rest length per motor.
  StepStatus step(std::int64_t time_ns, double dt_s, std::span<const double> tension_n,
                  std::span<double> commanded_rest_length_m) noexcept;

  double commanded_m(std::uint32_t motor) const noexcept { return motors_[motor].commanded_m(); }
  // Table time of the active table at caller time `time_ns` (0 at start).
  std::int64_t table_time_ns(std::int64_t time_ns) const noexcept { return time_ns - origin_ns_; }

 private:
  void swap_at_boundary(std::int64_t time_ns, StepStatus& status) noexcept;

  EndcapConfig config_;
  std::array<MotorLoop, kMaxMotorsPerEndcap> motors_{};
  EndcapTable active_{};
  EndcapTable pending_{};
  TableClock clock_{};
  bool has_active_ = false;
  bool has_pending_ = false;
  Mode mode_ = Mode::idle;
  FaultCause fault_ = FaultCause::none;
  std::int64_t origin_ns_ = 0;
  std::int64_t period_index_ = 0;
};

}  // namespace tensegrity::core
