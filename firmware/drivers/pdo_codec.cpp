// SPDX-License-Identifier: Apache-2.0
#include "firmware/drivers/pdo_codec.hpp"

#include <algorithm>

#include "firmware/drivers/byte_order.hpp"
#include "firmware/drivers/cob_id.hpp"

namespace tensegrity::fw::canopen {
namespace {

CanFrame make(Function f, std::uint8_t node_id, std::uint8_t dlc) {
  CanFrame frame;
  frame.id = cob_id(f, node_id);
  frame.dlc = dlc;
  return frame;
}

bool plain(const CanFrame& frame, std::uint8_t dlc) { return !frame.extended && !frame.rtr && frame.dlc == dlc; }

}  // namespace

CanFrame encode_drive_rpdo1(std::uint8_t node_id, const DriveRpdo1& pdo) {
  CanFrame f = make(Function::rpdo1, node_id, kDriveRpdo1Bytes);
  put_u16(&f.data[0], pdo.controlword);
  put_i32(&f.data[2], pdo.target_position_counts);
  return f;
}

bool decode_drive_rpdo1(const CanFrame& frame, DriveRpdo1& pdo) {
  if (!plain(frame, kDriveRpdo1Bytes)) return false;
  pdo.controlword = get_u16(&frame.data[0]);
  pdo.target_position_counts = get_i32(&frame.data[2]);
  return true;
}

CanFrame encode_drive_tpdo1(std::uint8_t node_id, const DriveTpdo1& pdo) {
  CanFrame f = make(Function::tpdo1, node_id, kDriveTpdo1Bytes);
  put_u16(&f.data[0], pdo.statusword);
  put_i32(&f.data[2], pdo.actual_position_counts);
  return f;
}

bool decode_drive_tpdo1(const CanFrame& frame, DriveTpdo1& pdo) {
  if (!plain(frame, kDriveTpdo1Bytes)) return false;
  pdo.statusword = get_u16(&frame.data[0]);
  pdo.actual_position_counts = get_i32(&frame.data[2]);
  return true;
}

CanFrame encode_drive_tpdo2(std::uint8_t node_id, const DriveTpdo2& pdo) {
  CanFrame f = make(Function::tpdo2, node_id, kDriveTpdo2Bytes);
  put_i32(&f.data[0], pdo.actual_velocity_counts_per_s);
  f.data[4] = static_cast<std::uint8_t>(pdo.mode_display);
  return f;
}

bool decode_drive_tpdo2(const CanFrame& frame, DriveTpdo2& pdo) {
  if (!plain(frame, kDriveTpdo2Bytes)) return false;
  pdo.actual_velocity_counts_per_s = get_i32(&frame.data[0]);
  pdo.mode_display = static_cast<std::int8_t>(frame.data[4]);
  return true;
}

CanFrame encode_load_cell_tpdo1(std::uint8_t node_id, const LoadCellTpdo1& pdo) {
  CanFrame f = make(Function::tpdo1, node_id, kLoadCellTpdo1Bytes);
  for (std::size_t ch = 0; ch < 2; ++ch) {
    put_i24(&f.data[3 * ch], std::clamp(pdo.tension_mn[ch], kLoadCellTensionMinMn, kLoadCellTensionMaxMn));
  }
  f.data[6] = pdo.status;
  f.data[7] = pdo.sequence;
  return f;
}

bool decode_load_cell_tpdo1(const CanFrame& frame, LoadCellTpdo1& pdo) {
  if (!plain(frame, kLoadCellTpdo1Bytes)) return false;
  if ((frame.data[6] & kLoadCellReservedMask) != 0) return false;
  pdo.tension_mn = {get_i24(&frame.data[0]), get_i24(&frame.data[3])};
  pdo.status = frame.data[6];
  pdo.sequence = frame.data[7];
  return true;
}

CanFrame encode_sync(std::uint8_t counter) {
  CanFrame f = make(Function::sync_or_emcy, 0, counter == 0 ? 0 : 1);
  f.data[0] = counter;
  return f;
}

bool decode_sync(const CanFrame& frame, std::uint8_t& counter) {
  if (frame.extended || frame.rtr || frame.id != kSyncCobId) return false;
  if (frame.dlc == 0) {
    counter = 0;
    return true;
  }
  if (frame.dlc != 1 || frame.data[0] < 1 || frame.data[0] > kSyncCounterMax) return false;
  counter = frame.data[0];
  return true;
}

}  // namespace tensegrity::fw::canopen
