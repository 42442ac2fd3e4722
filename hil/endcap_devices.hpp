// SPDX-License-Identifier: Apache-2.0
// Everything on one end cap's CAN bus except its computer: one emulated CiA 402
// drive per cable the end cap owns (node ids 1, 3, ... as in the end cap's
// config) and the two-channel load cell (node 2; channel m measures motor m).
// The world stepper feeds it the model's state and reads back, per cable, the
// preferred rest length the drives command.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "firmware/drivers/spool_geometry.hpp"
#include "hil/devices/cia402_drive.hpp"
#include "hil/devices/load_cell.hpp"

namespace tensegrity::hil {

inline constexpr std::array<std::uint8_t, 4> kDriveNodeIds{1, 3, 4, 5};
inline constexpr std::uint8_t kLoadCellNodeId = 2;

struct EndcapDeviceSummary {
  std::uint64_t rpdos = 0;
  std::uint64_t emcy_sent = 0;
  std::vector<std::string> drive_states;  // per motor, CiA 402 state name
  // Per motor, the interpolation period (0x60C2) its end cap gave it: the robot's step.
  std::vector<std::int64_t> drive_period_ns;
  bool load_cell_stuck = false;
};

class EndcapDevices {
 public:
  // `cables`: the model's cable index of each motor, in motor order.
  // `max_rest_length_m`: where a released (free-spooling) cable ends up.
  EndcapDevices(int endcap, std::vector<int> cables, const fw::SpoolGeometry& spool, double max_rest_length_m,
                bool lockstep);

  int endcap() const { return endcap_; }
  std::size_t motor_count() const { return drives_.size(); }
  const std::vector<int>& cables() const { return cables_; }
  std::uint8_t drive_node(std::size_t motor) const { return kDriveNodeIds[motor]; }

  void power_on(std::int64_t now_ns, FrameOut& out);
  // A frame from the end cap; answers go to `out`. Marks RPDO1 receipt per drive.
  void on_frame(const CanFrame& frame, std::int64_t now_ns, FrameOut& out);
  // Heartbeats and fault-reaction progress.
  void tick(std::int64_t now_ns, FrameOut& out);
  // The plant's state after the last physics step, whole-model spans.
  void update_from_model(std::span<const double> rest_length_m, std::span<const double> rest_rate_m_per_s,
                         std::span<const double> tension_n, std::int64_t now_ns);
  // Lockstep: the sensor PDOs of this tick (to go out before SYNC).
  void emit_sensors(FrameOut& out);

  // Barrier bookkeeping for one lockstep tick.
  void clear_rpdo_marks() { rpdo_seen_.fill(false); }
  bool all_rpdos() const;
  std::string missing_rpdo_nodes() const;  // "1, 3"

  // Start gate (see SimCia402Drive::hold_enable).
  bool at_gate() const;
  void release_gate();
  bool any_follows() const;
  void on_connection_lost();

  // Per cable of this end cap: the drive's target through the spool when it
  // follows one; a drive that is not enabled or is faulted holds its cable
  // (keeps the model's current rest length); a released drive pays it out.
  void preferred(std::span<const double> rest_length_m, std::span<double> preferred_m) const;

  // Fault injection.
  void fault_drive(std::size_t motor, std::uint16_t code, bool release, std::int64_t now_ns, FrameOut& out);
  void silence_drive(std::size_t motor, bool silent);
  // The spool runs free while the drive carries on unaware (a slipping clutch, a
  // snapped cable): the cable pays out as a released one does, no EMCY.
  void release_spool(std::size_t motor) { released_.at(motor) = true; }
  // The spool seizes (a jammed gearbox): the cable keeps its length, the drive
  // carries on unaware.
  void seize_spool(std::size_t motor) { seized_.at(motor) = true; }
  // A power cycle of one device: boot-up message, pre-operational, unpowered
  // (a drive comes back in switch on disabled, unconfigured); answers to `out`.
  void reboot_drive(std::size_t motor, std::int64_t now_ns, FrameOut& out) { drives_.at(motor).reboot(now_ns, out); }
  void reboot_load_cell(std::int64_t now_ns, FrameOut& out) { load_cell_.reboot(now_ns, out); }
  void set_load_cell_stuck(bool stuck) { load_cell_.set_stuck(stuck); }
  void start_load_cell_drift(double n_per_s, std::int64_t now_ns) { load_cell_.start_drift(n_per_s, now_ns); }

  SimCia402Drive& drive(std::size_t motor) { return drives_[motor]; }
  const SimCia402Drive& drive(std::size_t motor) const { return drives_[motor]; }
  SimLoadCell& load_cell() { return load_cell_; }
  EndcapDeviceSummary summary() const;

 private:
  int endcap_;
  std::vector<int> cables_;
  fw::SpoolGeometry spool_;
  double max_rest_length_m_;
  std::vector<SimCia402Drive> drives_;
  SimLoadCell load_cell_{kLoadCellNodeId};
  std::array<bool, 4> rpdo_seen_{};
  std::array<bool, 4> released_{};
  std::array<bool, 4> seized_{};
};

}  // namespace tensegrity::hil
