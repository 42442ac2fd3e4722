// SPDX-License-Identifier: Apache-2.0
// CANopen puts every multi-byte value on the wire little-endian (CiA 301 7.1).
#pragma once

#include <cstddef>
#include <cstdint>

namespace tensegrity::fw::canopen {

inline void put_u16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
inline void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline void put_i32(std::uint8_t* p, std::int32_t v) { put_u32(p, static_cast<std::uint32_t>(v)); }
// INTEGER24: two's complement in 3 bytes; v must fit.
inline void put_i24(std::uint8_t* p, std::int32_t v) {
  const auto u = static_cast<std::uint32_t>(v);
  for (std::size_t i = 0; i < 3; ++i) p[i] = static_cast<std::uint8_t>(u >> (8 * i));
}

inline std::uint16_t get_u16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }
inline std::uint32_t get_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}
inline std::int32_t get_i32(const std::uint8_t* p) { return static_cast<std::int32_t>(get_u32(p)); }
inline std::int32_t get_i24(const std::uint8_t* p) {
  std::uint32_t u =
      static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 | static_cast<std::uint32_t>(p[2]) << 16;
  if ((u & 0x80'0000U) != 0) u |= 0xFF00'0000U;  // sign-extend
  return static_cast<std::int32_t>(u);
}

}  // namespace tensegrity::fw::canopen
