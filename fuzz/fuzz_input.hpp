// SPDX-License-Identifier: Apache-2.0
// The fuzzer's bytes read as a stream of plain values; past the end every value reads
// as zero, so a short input is still a whole run.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace tensegrity::fuzz {

struct Input {
  const std::uint8_t* at;
  std::size_t left;
  template <typename T>
  T take() {
    T v{};
    const std::size_t n = left < sizeof v ? left : sizeof v;
    std::memcpy(&v, at, n);
    at += n;
    left -= n;
    return v;
  }
};

}  // namespace tensegrity::fuzz
