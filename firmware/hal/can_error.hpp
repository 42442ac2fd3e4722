// SPDX-License-Identifier: Apache-2.0
// Bus error reports. The class bits are Linux's CAN_ERR_* (linux/can/error.h), so
// a SocketCAN error frame and a UDP error datagram decode the same way; they are
// repeated here because the UDP path must build where linux/can.h is absent.
#pragma once

#include <cstdint>

#include "firmware/hal/can_bus.hpp"
#include "firmware/hal/can_frame.hpp"

namespace tensegrity::fw::can_error {

inline constexpr std::uint32_t kTxTimeout = 0x001;
inline constexpr std::uint32_t kLostArbitration = 0x002;
inline constexpr std::uint32_t kController = 0x004;  // data[1]: passive/warning detail
inline constexpr std::uint32_t kProtocol = 0x008;
inline constexpr std::uint32_t kTransceiver = 0x010;
inline constexpr std::uint32_t kNoAck = 0x020;
inline constexpr std::uint32_t kBusOff = 0x040;
inline constexpr std::uint32_t kBusError = 0x080;
inline constexpr std::uint32_t kRestarted = 0x100;
inline constexpr std::uint32_t kClassMask = 0x1FF;

// Fold one error report (class bits in `error_class`) into the counters: bus-off
// sets the flag, a controller restart clears it.
inline void apply_error_report(CanCounters& counters, std::uint32_t error_class) {
  ++counters.error_frames;
  counters.last_error_class = error_class & kClassMask;
  if ((error_class & kBusOff) != 0) counters.bus_off = true;
  if ((error_class & kRestarted) != 0) counters.bus_off = false;
}

}  // namespace tensegrity::fw::can_error
