// SPDX-License-Identifier: Apache-2.0
// Text form of a CAN bus choice, as given on a command line or in a config file:
//   udp:HOST:PORT[,bind=HOST:PORT][,batch]
//                                    frames over UDP to HOST:PORT, taken only from
//                                    HOST:PORT (docs/design/udp-can.md); bind defaults to
//                                    127.0.0.1:0 (any port, loopback only); batch:
//                                    send a cycle's frames as one version-2 datagram
//   socketcan:IFNAME                 a Linux CAN interface, e.g. can0 or vcan0
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace tensegrity::fw {

struct UdpEndpoint {
  // Loopback unless told: a bus bound to every address would be reachable from
  // the whole network, and it carries the drives' positions and the tensions.
  std::string host = "127.0.0.1";  // IPv4 address or host name
  std::uint16_t port = 0;
};

struct CanBusSpec {
  enum class Kind : std::uint8_t { udp, socketcan };
  Kind kind = Kind::udp;
  UdpEndpoint remote;          // udp
  UdpEndpoint bind;            // udp
  bool batch = false;          // udp: send version 2 (the peer must read it)
  std::string interface_name;  // socketcan
};

// "HOST:PORT"; port 0..65535, host non-empty.
bool parse_udp_endpoint(std::string_view text, UdpEndpoint& out, std::string& error);
// False with a one-line reason in `error` for anything malformed.
bool parse_can_bus_spec(std::string_view spec, CanBusSpec& out, std::string& error);

}  // namespace tensegrity::fw
