// SPDX-License-Identifier: Apache-2.0
#include "firmware/hal/make_can_bus.hpp"

#include "firmware/hal/can_bus_spec.hpp"
#include "firmware/hal/socketcan_bus.hpp"
#include "firmware/hal/udp_can_bus.hpp"

namespace tensegrity::fw {

MakeCanBusResult make_can_bus(const std::string& spec) {
  MakeCanBusResult result;
  CanBusSpec parsed;
  std::string error;
  if (!parse_can_bus_spec(spec, parsed, error)) {
    result.error = "CAN bus '" + spec + "': " + error;
    return result;
  }
  if (parsed.kind == CanBusSpec::Kind::socketcan) {
    result.bus = SocketCanBus::open(parsed.interface_name, error);
  } else {
    result.bus = UdpCanBus::open(UdpCanConfig{parsed.remote, parsed.bind, parsed.batch}, error);
  }
  if (!result.bus) result.error = "CAN bus '" + spec + "': " + error;
  return result;
}

}  // namespace tensegrity::fw
