// SPDX-License-Identifier: Apache-2.0
// An end cap's emergency stops as they travel on the wire (Heartbeat_ and
// CommandAck_ life_id / estops_received; Command_ lives_seen / estops_seen): the
// random id of the program's life, so a count from an earlier life never matches,
// and the count taken in it. Shared by the end cap's command gate and the ground.
#pragma once

#include <cstdint>

namespace tensegrity::fw::comms {

struct EstopCount {
  std::uint32_t life_id = 0;  // 0: none heard (an end cap draws a non-zero one)
  std::uint32_t count = 0;
  bool operator==(const EstopCount&) const = default;
};

}  // namespace tensegrity::fw::comms
