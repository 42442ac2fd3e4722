// SPDX-License-Identifier: Apache-2.0
// An emulated CiA 402 drive in cyclic synchronous position mode: power state
// machine, CSP target latching, TPDO1/TPDO2, EMCY on faults, heartbeat.
//
// Two ways to use it:
// - unit tests (defaults): an ideal drive: at SYNC the position jumps to the
//   latched target and the drive answers with its TPDOs;
// - the HIL emulator: the actual position comes from outside (the model's rest
//   length through the spool, set_actual()), and the TPDOs are emitted explicitly
//   (emit_tpdos(), before the SYNC that the end cap's cycle should see them with)
//   instead of on SYNC. The emulator reads target_counts() and follows_target()
//   to drive the model's actuator.
#pragma once

#include <cstdint>
#include <vector>

#include "firmware/drivers/cia402.hpp"
#include "firmware/drivers/pdo_codec.hpp"
#include "hil/devices/sim_node.hpp"

namespace tensegrity::hil {

class SimCia402Drive final : public SimNode {
 public:
  explicit SimCia402Drive(std::uint8_t node_id) : SimNode(node_id) {}

  // false: the position comes from set_actual() (HIL); true: the ideal drive.
  bool ideal_position = true;
  // false: TPDOs only through emit_tpdos() (HIL lockstep).
  bool tpdo_on_sync = true;
  // Start gate: while set, "enable operation" leaves the drive in switched on
  // (remembered); release_enable_gate() then enables every drive that asked, in
  // the same tick, so all end caps start their tables in phase.
  bool hold_enable = false;

  // Enters fault reaction (EMCY sent now), then fault on the next tick.
  void inject_fault(std::uint16_t error_code, std::int64_t now_ns, FrameOut& out);
  void tick(std::int64_t now_ns, FrameOut& out) override;

  void set_actual(std::int32_t position_counts, std::int32_t velocity_counts_per_s);
  void emit_tpdos(FrameOut& out) const;
  // Waiting at the start gate: switched on, the master asking for operation enabled.
  bool at_enable_gate() const;
  void release_enable_gate();
  // The master stopped talking (its process died): CiA 402 "abort connection"
  // reaction, option disable voltage. The drive stops following targets and
  // must be brought up again. (The HIL's kill_endcap says so directly; a drive
  // whose 0x1016 watches the end cap finds out by itself: on_heartbeat_lost.)
  void on_connection_lost();
  // 0x6007 as configured (power-on value: fault signal).
  canopen::AbortConnectionOption abort_connection_option() const { return abort_option_; }
  // Device time at which the drive last left operation enabled (-1: never).
  std::int64_t left_enabled_ns() const { return left_enabled_ns_; }
  // Operation enabled in CSP and answering: the motor follows target_counts().
  bool follows_target() const;

  canopen::Cia402State state() const { return state_; }
  std::uint16_t statusword() const;
  std::int8_t mode() const { return mode_; }
  std::int32_t position_counts() const { return position_counts_; }
  std::int32_t target_counts() const { return target_counts_; }
  std::uint64_t rpdos_received() const { return rpdos_received_; }
  std::uint64_t emcy_sent() const { return emcy_sent_; }
  std::uint16_t last_fault_code() const { return last_fault_code_; }
  std::vector<std::uint16_t> controlwords;  // every controlword received, in order
  bool log_controlwords = true;             // the HIL turns the log off (it would grow)
  // The periods its master gave it: 0x1006 (0 until written) and 0x60C2 (power-on
  // 1 ms); the ideal drive's velocity is the step over the interpolation period.
  std::int64_t cycle_period_ns() const { return cycle_period_us_ * 1'000; }
  std::int64_t interpolation_period_ns() const { return canopen::period_ns(interpolation_); }

 protected:
  std::uint32_t od_read(canopen::SdoAddress address, std::uint32_t& value, std::uint8_t& size) override;
  std::uint32_t od_write(canopen::SdoAddress address, std::uint32_t value, std::uint8_t size) override;
  void on_reset_node() override;
  void on_heartbeat_lost(std::int64_t now_ns, FrameOut& out) override;
  void on_pdo_or_sync(const CanFrame& frame, std::int64_t now_ns, FrameOut& out) override;

 private:
  void apply_controlword(std::uint16_t controlword);
  std::uint32_t read_period(canopen::SdoAddress address, std::uint32_t& value, std::uint8_t& size) const;
  std::uint32_t write_period(canopen::SdoAddress address, std::uint32_t value, std::uint8_t size);
  void apply_controlword_to_state(std::uint16_t controlword);

  canopen::Cia402State state_ = canopen::Cia402State::switch_on_disabled;
  std::int8_t mode_ = 0;
  std::int32_t position_counts_ = 0;
  std::int32_t velocity_counts_per_s_ = 0;
  std::int32_t target_counts_ = 0;
  std::uint16_t last_controlword_ = 0;
  std::uint16_t pending_fault_code_ = 0;
  std::uint16_t last_fault_code_ = 0;
  bool enable_requested_ = false;
  std::uint64_t rpdos_received_ = 0;
  std::uint64_t emcy_sent_ = 0;
  canopen::AbortConnectionOption abort_option_ = canopen::AbortConnectionOption::fault_signal;
  std::int64_t left_enabled_ns_ = -1;
  std::int64_t now_ns_ = 0;  // of the frame or tick being handled
  std::uint32_t cycle_period_us_ = 0;
  canopen::InterpolationPeriod interpolation_{};
};

}  // namespace tensegrity::hil
