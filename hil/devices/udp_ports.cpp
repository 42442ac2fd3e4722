// SPDX-License-Identifier: Apache-2.0
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

#include "hil/devices/udp_ports.hpp"

namespace tensegrity::hil {
namespace {

// The low end of the kernel's ephemeral range (net.ipv4.ip_local_port_range).
int ephemeral_low() {
  std::ifstream in("/proc/sys/net/ipv4/ip_local_port_range");
  int low = 0;
  return (in >> low) && low > 2048 && low <= 65535 ? low : 32768;
}

}  // namespace

std::vector<std::uint16_t> free_udp_ports(int count) {
  // Below the ephemeral range: a port chosen there and released for the end cap to
  // bind could be handed to any socket that binds port 0 (a DDS participant's
  // sender, another test) before the end cap starts ("Address already in use" in a
  // CI run). Below it only explicit binds compete. A random start keeps two
  // launchers apart.
  const int high = ephemeral_low();
  const int low = high - kLauncherPortSpan;
  std::vector<int> fds;
  std::vector<std::uint16_t> ports;
  const auto release = [&fds] {
    for (int f : fds) ::close(f);
  };
  const int start = static_cast<int>(std::random_device{}() % static_cast<unsigned>(kLauncherPortSpan));
  for (int i = 0; i < kLauncherPortSpan && static_cast<int>(ports.size()) < count; ++i) {
    const int port = low + (start + i) % kLauncherPortSpan;
    const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd < 0) {
      release();
      throw std::runtime_error(std::string("cannot open a UDP socket: ") + std::strerror(errno));
    }
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = htons(static_cast<std::uint16_t>(port));
    if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
      ::close(fd);  // taken: try the next
      continue;
    }
    fds.push_back(fd);  // held until all are chosen, so no two are the same
    ports.push_back(static_cast<std::uint16_t>(port));
  }
  release();
  if (static_cast<int>(ports.size()) < count) {
    throw std::runtime_error("cannot find " + std::to_string(count) +
                             " free UDP ports in 127.0.0.1:" + std::to_string(low) + ".." + std::to_string(high - 1));
  }
  return ports;
}

}  // namespace tensegrity::hil
