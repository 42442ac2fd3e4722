// SPDX-License-Identifier: Apache-2.0
// Emergency messages (CiA 301 7.2.7): 0x080 + node id, 8 bytes:
// error code u16 | error register u8 (object 0x1001) | 5 manufacturer bytes.
#pragma once

#include <array>
#include <cstdint>

#include "firmware/hal/can_frame.hpp"

namespace tensegrity::fw::canopen {

struct EmcyMessage {
  std::uint16_t error_code = 0;  // 0x0000: "error reset / no error"
  std::uint8_t error_register = 0;
  std::array<std::uint8_t, 5> manufacturer{};
  friend bool operator==(const EmcyMessage&, const EmcyMessage&) = default;
};

// Error register bits (object 0x1001).
inline constexpr std::uint8_t kErrRegGeneric = 0x01;
inline constexpr std::uint8_t kErrRegCurrent = 0x02;
inline constexpr std::uint8_t kErrRegVoltage = 0x04;
inline constexpr std::uint8_t kErrRegTemperature = 0x08;
inline constexpr std::uint8_t kErrRegCommunication = 0x10;
inline constexpr std::uint8_t kErrRegProfile = 0x20;
inline constexpr std::uint8_t kErrRegManufacturer = 0x80;

CanFrame encode_emcy(std::uint8_t node_id, const EmcyMessage& message);
// False unless dlc is 8 (the consumer's check of node/function is the caller's).
bool decode_emcy(const CanFrame& frame, EmcyMessage& message);
// The code's meaning from CiA 301 / CiA 402 tables: exact where known, else its class.
const char* emcy_error_text(std::uint16_t error_code);

}  // namespace tensegrity::fw::canopen
