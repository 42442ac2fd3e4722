// SPDX-License-Identifier: Apache-2.0
// Expedited SDO frames (CiA 301 7.2.4.3): at most 4 data bytes, one request and
// one response. Used by the client here and by emulated servers (tests, HIL).
// Every SDO frame is 8 bytes: command | index u16 | subindex | data/abort code u32.
#pragma once

#include <cstdint>

#include "firmware/hal/can_frame.hpp"

namespace tensegrity::fw::canopen {

struct SdoAddress {
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  friend bool operator==(const SdoAddress&, const SdoAddress&) = default;
};

enum class SdoKind : std::uint8_t {
  download_request,   // client -> server, expedited
  download_response,  // server -> client
  upload_request,     // client -> server
  upload_response,    // server -> client, expedited
  abort,              // either way
  unsupported,        // segmented/block transfers, or an invalid command byte
};

struct SdoMessage {
  SdoKind kind = SdoKind::unsupported;
  SdoAddress address;
  std::uint32_t value = 0;  // data (little-endian, zero-extended) or abort code
  std::uint8_t size = 0;    // data bytes 1..4; 0 = not indicated
};

// Requests go to 0x600 + node, responses and aborts to 0x580 + node (a client
// abort: set the id to 0x600 + node).
CanFrame encode_sdo(std::uint8_t node_id, const SdoMessage& message);
// `from_server` tells the direction, which the command byte alone does not.
// False when dlc != 8 or the frame is not an SDO at all.
bool decode_sdo(const CanFrame& frame, bool from_server, SdoMessage& message);

}  // namespace tensegrity::fw::canopen
