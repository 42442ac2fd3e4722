// SPDX-License-Identifier: Apache-2.0
// One classic CAN 2.0 frame, independent of any OS header so the control code,
// the UDP transport and the emulator share it.
#pragma once

#include <array>
#include <cstdint>

namespace tensegrity::fw {

inline constexpr std::uint32_t kCanStandardIdMax = 0x7FF;
inline constexpr std::uint32_t kCanExtendedIdMax = 0x1FFF'FFFF;
inline constexpr std::uint8_t kCanMaxDlc = 8;

struct CanFrame {
  std::uint32_t id = 0;  // 11-bit, or 29-bit when `extended`
  bool extended = false;
  bool rtr = false;
  std::uint8_t dlc = 0;  // 0..8; an RTR frame's dlc is the length it requests
  std::array<std::uint8_t, 8> data{};
};

// A frame that a bus would carry: id within its range, dlc 0..8.
constexpr bool is_valid(const CanFrame& frame) {
  const std::uint32_t id_max = frame.extended ? kCanExtendedIdMax : kCanStandardIdMax;
  return frame.id <= id_max && frame.dlc <= kCanMaxDlc;
}

constexpr bool operator==(const CanFrame& a, const CanFrame& b) {
  if (a.id != b.id || a.extended != b.extended || a.rtr != b.rtr || a.dlc != b.dlc) {
    return false;
  }
  // Bytes past dlc are not on the wire, so they do not make two frames differ.
  for (std::uint8_t i = 0; i < a.dlc && i < kCanMaxDlc; ++i) {
    if (a.data[i] != b.data[i]) return false;
  }
  return true;
}

}  // namespace tensegrity::fw
