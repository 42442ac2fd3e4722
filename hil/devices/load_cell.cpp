// SPDX-License-Identifier: Apache-2.0
#include "hil/devices/load_cell.hpp"

#include <cmath>

#include "firmware/drivers/sdo_abort.hpp"

namespace tensegrity::hil {

using namespace fw::canopen;

namespace {
std::int32_t to_mn(double n) {
  const double mn = std::round(n * 1000.0);
  // Saturate here too: llround of an out-of-range double is undefined.
  if (!(mn > static_cast<double>(kLoadCellTensionMinMn))) return kLoadCellTensionMinMn;
  if (mn > static_cast<double>(kLoadCellTensionMaxMn)) return kLoadCellTensionMaxMn;
  return static_cast<std::int32_t>(mn);
}
}  // namespace

void SimLoadCell::set_tensions_n(double ch0_n, double ch1_n, std::int64_t now_ns) {
  if (stuck()) return;
  const double drift_n =
      drift_n_per_s_ == 0.0 ? 0.0 : drift_n_per_s_ * static_cast<double>(now_ns - drift_since_ns_) * 1e-9;
  sample.tension_mn = {to_mn(ch0_n + drift_n), to_mn(ch1_n + drift_n)};
}

void SimLoadCell::set_stuck(bool is_stuck) { advance_sequence = !is_stuck; }

void SimLoadCell::start_drift(double drift_n_per_s, std::int64_t now_ns) {
  drift_n_per_s_ = drift_n_per_s;
  drift_since_ns_ = now_ns;
}

void SimLoadCell::emit_tpdo(FrameOut& out) {
  if (!answering() || nmt_state() != NmtState::operational) return;
  if (advance_sequence) ++sample.sequence;
  out.push_back(encode_load_cell_tpdo1(node_id(), sample));
}

std::uint32_t SimLoadCell::od_read(SdoAddress a, std::uint32_t& value, std::uint8_t& size) {
  if (a.index == 0x1000 && a.subindex == 0) {
    value = 0x0004'0194;  // CiA 404 measuring device, analogue input
    size = 4;
    return 0;
  }
  return sdo_abort::kNoObject;
}

std::uint32_t SimLoadCell::od_write(SdoAddress a, std::uint32_t, std::uint8_t) {
  return a.index == 0x1000 ? sdo_abort::kReadOnly : sdo_abort::kNoObject;
}

void SimLoadCell::on_pdo_or_sync(const CanFrame& frame, std::int64_t, FrameOut& out) {
  std::uint8_t counter = 0;
  if (!decode_sync(frame, counter)) return;
  if (tpdo_on_sync) emit_tpdo(out);
}

}  // namespace tensegrity::hil
