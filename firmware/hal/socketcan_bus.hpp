// SPDX-License-Identifier: Apache-2.0
// CanBus on a Linux CAN interface (raw socket, AF_CAN/CAN_RAW). Error frames are
// enabled and folded into counters(): bus-off sets the flag, a controller restart
// clears it. Only this file's .cpp includes linux/can.h.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "firmware/hal/can_bus.hpp"

namespace tensegrity::fw {

// Accept a frame when (frame.id & mask) == (id & mask) and its id kind (11/29-bit)
// matches `extended`.
struct CanIdFilter {
  std::uint32_t id = 0;
  std::uint32_t mask = 0;
  bool extended = false;
};

class SocketCanBus final : public CanBus {
 public:
  // nullptr and a one-line reason in `error`, e.g. when the kernel has no CAN
  // support or the interface does not exist.
  static std::unique_ptr<SocketCanBus> open(const std::string& interface_name, std::string& error);
  ~SocketCanBus() override;
  SocketCanBus(const SocketCanBus&) = delete;
  SocketCanBus& operator=(const SocketCanBus&) = delete;

  CanResult send(const CanFrame& frame) override;
  CanResult receive(CanFrame& frame, std::int64_t timeout_ns) override;
  CanCounters counters() const override { return counters_; }

  // Replaces the kernel's receive filter; an empty list receives no data frames
  // (error reports still arrive). Call at set-up, not in the control loop.
  CanResult set_filters(std::span<const CanIdFilter> filters);
  const std::string& interface_name() const { return interface_name_; }
  int last_errno() const { return last_errno_; }

 private:
  SocketCanBus(int fd, std::string interface_name);

  int fd_;
  std::string interface_name_;
  CanCounters counters_;
  int last_errno_ = 0;
};

}  // namespace tensegrity::fw
