// SPDX-License-Identifier: Apache-2.0
// Why a received frame was ignored. Counted per reason so a bad node, a wrong
// mapping or bus noise each show up as their own number.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace tensegrity::fw::canopen {

enum class RxDrop : std::uint8_t {
  extended_id,          // CANopen here uses 11-bit ids only
  rtr,                  // remote frames are not served
  unexpected_function,  // a COB-ID function we do not consume (NMT, RPDO, SDO request, ...)
  unknown_node,         // a function we consume, from a node that is not ours
  bad_length,           // dlc does not match the mapping
  bad_value,            // decodes, but a field is out of range (statusword, NMT state, ...)
  unexpected_sdo,       // SDO response with no transfer pending, or for another object
  count,
};

const char* to_string(RxDrop reason);

class RxDropCounters {
 public:
  void count(RxDrop reason) { ++counts_[static_cast<std::size_t>(reason)]; }
  std::uint64_t operator[](RxDrop reason) const { return counts_[static_cast<std::size_t>(reason)]; }
  std::uint64_t total() const {
    std::uint64_t sum = 0;
    for (const std::uint64_t c : counts_) sum += c;
    return sum;
  }

 private:
  std::array<std::uint64_t, static_cast<std::size_t>(RxDrop::count)> counts_{};
};

}  // namespace tensegrity::fw::canopen
