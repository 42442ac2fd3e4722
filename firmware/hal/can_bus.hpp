// SPDX-License-Identifier: Apache-2.0
// The firmware's view of a CAN bus. The control loop calls it every cycle, so
// results are codes, never exceptions, and nothing here allocates.
#pragma once

#include <cstdint>

#include "firmware/hal/can_frame.hpp"

namespace tensegrity::fw {

enum class CanResult : std::uint8_t {
  ok,
  timeout,        // nothing arrived in time (or at once, for timeout 0)
  would_block,    // transmit queue full; the frame was not sent
  invalid_frame,  // refused to send: id out of range or dlc > 8
  bus_off,        // controller is bus-off; nothing can be sent
  io_error,       // the OS reported an error; see the backend's last_errno()
};

const char* to_string(CanResult result);

struct CanCounters {
  std::uint64_t tx_frames = 0;
  std::uint64_t rx_frames = 0;
  std::uint64_t tx_dropped = 0;         // send() refused: queue full, bus-off, invalid frame
  std::uint64_t rx_malformed = 0;       // arrived but untrustworthy; dropped
  std::uint64_t rx_unknown_sender = 0;  // UDP: a datagram from anyone but the peer; dropped
  std::uint64_t error_frames = 0;       // bus error reports (see can_error.hpp)
  std::uint32_t last_error_class = 0;   // CAN_ERR_* class bits of the latest report
  bool bus_off = false;
};

class CanBus {
 public:
  virtual ~CanBus() = default;
  virtual CanResult send(const CanFrame& frame) = 0;
  // timeout_ns == 0: poll once; < 0: wait without limit. Data frames only; error
  // reports are absorbed into counters().
  virtual CanResult receive(CanFrame& frame, std::int64_t timeout_ns) = 0;
  // Sends what send() has queued. Most backends send at once and have nothing to
  // do; the UDP backend in batch mode gathers a cycle's frames into one datagram.
  // The control loop calls it once at the end of every cycle.
  virtual CanResult flush() { return CanResult::ok; }
  virtual CanCounters counters() const = 0;
};

}  // namespace tensegrity::fw
