// SPDX-License-Identifier: Apache-2.0
// Times that arrive over the wire (host times in commands, time-sync stamps) are
// checked against a range before any arithmetic on them: a signed overflow is
// undefined behaviour, and a peer chooses these numbers. Host time is a
// CLOCK_MONOTONIC reading, >= 0; 2^62 ns is 146 years, so differences and sums of
// two valid times never overflow.
#pragma once

#include <cstdint>
#include <optional>

namespace tensegrity::fw::comms {

inline constexpr std::int64_t kMaxWireTimeNs = std::int64_t{1} << 62;

constexpr bool valid_wire_time(std::int64_t t_ns) { return t_ns >= 0 && t_ns <= kMaxWireTimeNs; }

// a + b and a - b, or nothing when the exact result does not fit.
inline std::optional<std::int64_t> checked_add(std::int64_t a, std::int64_t b) {
  std::int64_t out = 0;
  if (__builtin_add_overflow(a, b, &out)) return std::nullopt;
  return out;
}
inline std::optional<std::int64_t> checked_sub(std::int64_t a, std::int64_t b) {
  std::int64_t out = 0;
  if (__builtin_sub_overflow(a, b, &out)) return std::nullopt;
  return out;
}
inline std::optional<std::int64_t> checked_mul(std::int64_t a, std::int64_t b) {
  std::int64_t out = 0;
  if (__builtin_mul_overflow(a, b, &out)) return std::nullopt;
  return out;
}

}  // namespace tensegrity::fw::comms
