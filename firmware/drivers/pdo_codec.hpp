// SPDX-License-Identifier: Apache-2.0
// Our fixed PDO mappings and SYNC, as pure encode/decode functions, used by the
// master and by emulated devices (tests, HIL). Table: docs/design/canopen.md.
//
//   drive RPDO1 0x200+id  6 bytes  controlword u16 | target position i32 (counts)
//   drive TPDO1 0x180+id  6 bytes  statusword u16  | actual position i32 (counts)
//   drive TPDO2 0x280+id  5 bytes  actual velocity i32 (counts/s) | mode display i8
//   load  TPDO1 0x180+id  8 bytes  tension ch0 i24 (mN) | ch1 i24 (mN) | status u8 | sequence u8
//   SYNC  0x080           0 bytes, or 1 byte counter 1..240
//
// Decoders return false on a wrong dlc/kind or a value outside its range; the
// caller has already checked the COB-ID.
#pragma once

#include <array>
#include <cstdint>

#include "firmware/hal/can_frame.hpp"

namespace tensegrity::fw::canopen {

struct DriveRpdo1 {
  std::uint16_t controlword = 0;
  std::int32_t target_position_counts = 0;
  friend bool operator==(const DriveRpdo1&, const DriveRpdo1&) = default;
};

struct DriveTpdo1 {
  std::uint16_t statusword = 0;
  std::int32_t actual_position_counts = 0;
  friend bool operator==(const DriveTpdo1&, const DriveTpdo1&) = default;
};

struct DriveTpdo2 {
  std::int32_t actual_velocity_counts_per_s = 0;
  std::int8_t mode_display = 0;  // 0x6061; 8 = cyclic synchronous position
  friend bool operator==(const DriveTpdo2&, const DriveTpdo2&) = default;
};

// Load-cell status bits; bits 5..7 are reserved and must be zero.
inline constexpr std::uint8_t kLoadCellCh0Valid = 0x01;
inline constexpr std::uint8_t kLoadCellCh1Valid = 0x02;
inline constexpr std::uint8_t kLoadCellCh0OverRange = 0x04;
inline constexpr std::uint8_t kLoadCellCh1OverRange = 0x08;
inline constexpr std::uint8_t kLoadCellAdcFault = 0x10;
inline constexpr std::uint8_t kLoadCellReservedMask = 0xE0;
// INTEGER24 in millinewtons: +-8388.607 N, far beyond the 500 N design load.
inline constexpr std::int32_t kLoadCellTensionMaxMn = 0x7F'FFFF;
inline constexpr std::int32_t kLoadCellTensionMinMn = -0x80'0000;

struct LoadCellTpdo1 {
  std::array<std::int32_t, 2> tension_mn{};  // encode saturates to the i24 range
  std::uint8_t status = 0;
  std::uint8_t sequence = 0;  // +1 per sample, wraps; repeats reveal a stale sensor
  friend bool operator==(const LoadCellTpdo1&, const LoadCellTpdo1&) = default;
};

inline constexpr std::uint8_t kDriveRpdo1Bytes = 6;
inline constexpr std::uint8_t kDriveTpdo1Bytes = 6;
inline constexpr std::uint8_t kDriveTpdo2Bytes = 5;
inline constexpr std::uint8_t kLoadCellTpdo1Bytes = 8;
inline constexpr std::uint8_t kSyncCounterMax = 240;

CanFrame encode_drive_rpdo1(std::uint8_t node_id, const DriveRpdo1& pdo);
bool decode_drive_rpdo1(const CanFrame& frame, DriveRpdo1& pdo);
CanFrame encode_drive_tpdo1(std::uint8_t node_id, const DriveTpdo1& pdo);
bool decode_drive_tpdo1(const CanFrame& frame, DriveTpdo1& pdo);
CanFrame encode_drive_tpdo2(std::uint8_t node_id, const DriveTpdo2& pdo);
bool decode_drive_tpdo2(const CanFrame& frame, DriveTpdo2& pdo);
CanFrame encode_load_cell_tpdo1(std::uint8_t node_id, const LoadCellTpdo1& pdo);
bool decode_load_cell_tpdo1(const CanFrame& frame, LoadCellTpdo1& pdo);

// counter 0: no counter byte (SYNC without counter, dlc 0).
CanFrame encode_sync(std::uint8_t counter = 0);
bool decode_sync(const CanFrame& frame, std::uint8_t& counter);

}  // namespace tensegrity::fw::canopen
