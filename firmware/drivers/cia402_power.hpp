// SPDX-License-Identifier: Apache-2.0
// Master side of the CiA 402 power state machine: from the state the drive
// reports and what we want of it, the controlword for this cycle. One step per
// cycle, so every transition is confirmed by a statusword before the next.
// A fault is never reset on our own: only after request_fault_reset().
#pragma once

#include <cstdint>

#include "firmware/drivers/cia402.hpp"

namespace tensegrity::fw::canopen {

class Cia402PowerControl {
 public:
  void request(PowerRequest request) { request_ = request; }
  PowerRequest requested() const { return request_; }
  // Effective while the drive is in fault; forgotten once it has left it.
  void request_fault_reset() { fault_reset_pending_ = true; }
  bool fault_reset_pending() const { return fault_reset_pending_; }

  std::uint16_t next_controlword(Cia402State state);
  std::uint16_t last_controlword() const { return last_; }

 private:
  std::uint16_t choose(Cia402State state);

  PowerRequest request_ = PowerRequest::disabled;
  bool fault_reset_pending_ = false;
  std::uint16_t last_ = 0;
};

}  // namespace tensegrity::fw::canopen
