// SPDX-License-Identifier: Apache-2.0
// Heartbeat consumer for one node (CiA 301 7.2.8.3.2.2): monitoring starts with
// the first heartbeat, and the node is lost when none arrives within the timeout.
#pragma once

#include <cstdint>

#include "firmware/drivers/nmt.hpp"

namespace tensegrity::fw::canopen {

struct HeartbeatStatus {
  NmtState state = NmtState::unknown;  // after a boot-up message: pre-operational
  bool seen = false;
  bool alive = false;
  std::int64_t last_seen_ns = 0;
  std::uint32_t boot_ups = 0;
  std::uint32_t losses = 0;
};

class HeartbeatMonitor {
 public:
  enum class Change : std::uint8_t { none, boot_up, restored, lost };

  explicit HeartbeatMonitor(std::int64_t timeout_ns) : timeout_ns_(timeout_ns) {}

  Change on_heartbeat(NmtState state, std::int64_t now_ns) {
    const bool was_lost = status_.seen && !status_.alive;
    status_.seen = true;
    status_.alive = true;
    status_.last_seen_ns = now_ns;
    if (state == NmtState::boot_up) {
      // A node enters pre-operational by itself right after its boot-up message.
      status_.state = NmtState::pre_operational;
      ++status_.boot_ups;
      return Change::boot_up;
    }
    status_.state = state;
    return was_lost ? Change::restored : Change::none;
  }

  Change poll(std::int64_t now_ns) {
    if (!status_.alive || now_ns - status_.last_seen_ns <= timeout_ns_) return Change::none;
    status_.alive = false;
    ++status_.losses;
    return Change::lost;
  }

  const HeartbeatStatus& status() const { return status_; }
  std::int64_t timeout_ns() const { return timeout_ns_; }

 private:
  std::int64_t timeout_ns_;
  HeartbeatStatus status_;
};

}  // namespace tensegrity::fw::canopen
