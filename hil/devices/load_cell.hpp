// SPDX-License-Identifier: Apache-2.0
// An emulated two-channel load cell (CiA 404-like, TPDO1 in docs/design/canopen.md).
// Unit tests script `sample` directly and let it answer SYNC; the HIL emulator
// feeds the model's tensions (set_tensions_n) and emits the TPDO before SYNC
// (emit_tpdo). Faults: a stuck sensor (value and sequence frozen: the master
// sees stale samples) and a drifting one (an offset growing with time).
#pragma once

#include <cstdint>

#include "firmware/drivers/pdo_codec.hpp"
#include "hil/devices/sim_node.hpp"

namespace tensegrity::hil {

class SimLoadCell final : public SimNode {
 public:
  explicit SimLoadCell(std::uint8_t node_id) : SimNode(node_id) {}

  canopen::LoadCellTpdo1 sample{{0, 0}, canopen::kLoadCellCh0Valid | canopen::kLoadCellCh1Valid, 0};
  bool advance_sequence = true;  // false: a stuck sensor repeating its sample
  bool tpdo_on_sync = true;      // false: only through emit_tpdo() (HIL lockstep)

  // The true tensions at `now_ns`; the sample is what the sensor reports of them.
  void set_tensions_n(double ch0_n, double ch1_n, std::int64_t now_ns);
  // Freezes the reported value and sequence (the master counts stale samples).
  void set_stuck(bool stuck);
  // Adds drift_n_per_s * (t - now) to every later reading, on both channels.
  void start_drift(double drift_n_per_s, std::int64_t now_ns);
  bool stuck() const { return !advance_sequence; }
  // One new sample (sequence advanced unless stuck) as TPDO1.
  void emit_tpdo(FrameOut& out);

 protected:
  std::uint32_t od_read(canopen::SdoAddress address, std::uint32_t& value, std::uint8_t& size) override;
  std::uint32_t od_write(canopen::SdoAddress address, std::uint32_t value, std::uint8_t size) override;
  void on_pdo_or_sync(const CanFrame& frame, std::int64_t now_ns, FrameOut& out) override;

 private:
  double drift_n_per_s_ = 0.0;
  std::int64_t drift_since_ns_ = 0;
};

}  // namespace tensegrity::hil
