// SPDX-License-Identifier: Apache-2.0
// CAN frames over UDP: one frame per datagram, exactly 20 bytes, little-endian.
//
//   offset size field
//   0      4    magic "TCAN"
//   4      1    version, 1
//   5      1    flags: bit0 extended id, bit1 RTR, bit2 error report; bits 3-7 zero
//   6      1    dlc, 0..8
//   7      1    reserved, zero
//   8      4    can_id u32: 11-bit (<= 0x7FF), or 29-bit when extended;
//               for an error report the CAN_ERR_* class bits (see can_error.hpp)
//   12     8    data; bytes past dlc are zero when sent and ignored when read
//
// A datagram of any other size, magic or version, with unknown flag bits, a
// nonzero reserved byte, dlc > 8 or an id out of range is dropped and counted,
// never passed on. Full description: docs/design/udp-can.md. Pure code, no OS headers,
// so the HIL emulator can reuse it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/hal/can_frame.hpp"

namespace tensegrity::fw::udp_can {

inline constexpr std::size_t kDatagramBytes = 20;
inline constexpr std::uint8_t kVersion = 1;
inline constexpr std::uint8_t kFlagExtended = 0x01;
inline constexpr std::uint8_t kFlagRtr = 0x02;
inline constexpr std::uint8_t kFlagError = 0x04;

using Datagram = std::array<std::uint8_t, kDatagramBytes>;

enum class Decoded : std::uint8_t {
  frame,         // a data/RTR frame
  error_report,  // frame.id holds the error class bits, frame.data the details
  bad_size,
  bad_magic,
  bad_version,
  bad_flags,
  bad_reserved,
  bad_dlc,
  bad_id,
};
inline constexpr std::size_t kDecodedCount = 9;

const char* to_string(Decoded d);

// Caller checks is_valid(frame) first; an invalid frame is encoded as given.
Datagram encode(const CanFrame& frame);
Datagram encode_error_report(std::uint32_t error_class, const std::array<std::uint8_t, 8>& detail);
Decoded decode(std::span<const std::uint8_t> datagram, CanFrame& frame);

namespace detail {
// The checks one frame's fields get in either version (udp_can_batch.hpp): flags,
// reserved byte(s), dlc, id range. `data` points at 8 bytes.
Decoded decode_fields(std::uint8_t flags, std::uint8_t dlc, bool reserved_zero, std::uint32_t id,
                      const std::uint8_t* data, CanFrame& frame);
std::uint32_t read_u32(const std::uint8_t* bytes);
}  // namespace detail

}  // namespace tensegrity::fw::udp_can
