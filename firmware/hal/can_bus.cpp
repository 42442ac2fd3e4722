// SPDX-License-Identifier: Apache-2.0
#include "firmware/hal/can_bus.hpp"

namespace tensegrity::fw {

const char* to_string(CanResult result) {
  switch (result) {
    case CanResult::ok: return "ok";
    case CanResult::timeout: return "timeout";
    case CanResult::would_block: return "transmit queue full";
    case CanResult::invalid_frame: return "invalid frame";
    case CanResult::bus_off: return "bus-off";
    case CanResult::io_error: return "I/O error";
  }
  return "unknown";
}

}  // namespace tensegrity::fw
