// SPDX-License-Identifier: Apache-2.0
// CiA 301 predefined connection set: an 11-bit COB-ID is a 4-bit function code
// and a 7-bit node id.
#pragma once

#include <cstdint>

namespace tensegrity::fw::canopen {

inline constexpr std::uint8_t kNodeIdMin = 1;
inline constexpr std::uint8_t kNodeIdMax = 127;

enum class Function : std::uint16_t {
  nmt = 0x000,
  sync_or_emcy = 0x080,  // node 0: SYNC; nodes 1..127: EMCY
  time = 0x100,
  tpdo1 = 0x180,
  rpdo1 = 0x200,
  tpdo2 = 0x280,
  rpdo2 = 0x300,
  tpdo3 = 0x380,
  rpdo3 = 0x400,
  tpdo4 = 0x480,
  rpdo4 = 0x500,
  sdo_tx = 0x580,  // server -> client (responses)
  sdo_rx = 0x600,  // client -> server (requests)
  heartbeat = 0x700,
};

inline constexpr std::uint16_t kSyncCobId = 0x080;

constexpr std::uint16_t cob_id(Function f, std::uint8_t node_id) {
  return static_cast<std::uint16_t>(static_cast<std::uint16_t>(f) + node_id);
}
constexpr Function function_of(std::uint32_t cob) { return static_cast<Function>(cob & 0x780U); }
constexpr std::uint8_t node_of(std::uint32_t cob) { return static_cast<std::uint8_t>(cob & 0x7FU); }
constexpr bool is_valid_node_id(std::uint8_t node_id) { return node_id >= kNodeIdMin && node_id <= kNodeIdMax; }

}  // namespace tensegrity::fw::canopen
