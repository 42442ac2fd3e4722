// SPDX-License-Identifier: Apache-2.0
// Network management (CiA 301 7.2.8): commands from the master and the
// heartbeat that every node produces (0x700 + id, one byte: its NMT state).
#pragma once

#include <cstdint>

#include "firmware/hal/can_frame.hpp"

namespace tensegrity::fw::canopen {

// Heartbeat objects (CiA 301 7.5.2.29-30). 0x1016 sub n (UNSIGNED32): bits 23-16
// the producer's node id, bits 15-0 the consumer time in ms (0: unused).
// 0x1017 (UNSIGNED16): this node's producer period in ms.
inline constexpr std::uint16_t kOdConsumerHeartbeatTime = 0x1016;
inline constexpr std::uint16_t kOdProducerHeartbeatTime = 0x1017;
inline constexpr std::uint32_t consumer_heartbeat_entry(std::uint8_t producer_node_id, std::uint16_t time_ms) {
  return (static_cast<std::uint32_t>(producer_node_id) << 16) | time_ms;
}

enum class NmtCommand : std::uint8_t {
  start = 0x01,
  stop = 0x02,
  enter_pre_operational = 0x80,
  reset_node = 0x81,
  reset_communication = 0x82,
};

enum class NmtState : std::uint8_t {
  boot_up = 0x00,  // sent once, as the first heartbeat after a (re)boot
  stopped = 0x04,
  operational = 0x05,
  pre_operational = 0x7F,
  unknown = 0xFF,  // never on the wire: no heartbeat seen yet
};

const char* to_string(NmtCommand command);
const char* to_string(NmtState state);

// node_id 0 addresses every node.
CanFrame encode_nmt(NmtCommand command, std::uint8_t node_id);
bool decode_nmt(const CanFrame& frame, NmtCommand& command, std::uint8_t& node_id);

CanFrame encode_heartbeat(std::uint8_t node_id, NmtState state);
// False when the byte is not a defined state (the toggle bit of node guarding
// is not used, so bit 7 set with other bits is invalid too).
bool decode_nmt_state(std::uint8_t byte, NmtState& state);

}  // namespace tensegrity::fw::canopen
