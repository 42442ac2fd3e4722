// SPDX-License-Identifier: Apache-2.0
// Opens the CAN bus named by a spec string (can_bus_spec.hpp), once at start-up.
#pragma once

#include <memory>
#include <string>

#include "firmware/hal/can_bus.hpp"

namespace tensegrity::fw {

struct MakeCanBusResult {
  std::unique_ptr<CanBus> bus;  // null on failure
  std::string error;            // one line naming the spec and the cause
  explicit operator bool() const { return bus != nullptr; }
};

MakeCanBusResult make_can_bus(const std::string& spec);

}  // namespace tensegrity::fw
