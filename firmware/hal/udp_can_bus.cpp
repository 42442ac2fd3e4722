// SPDX-License-Identifier: Apache-2.0
#include "firmware/hal/udp_can_bus.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "firmware/hal/can_error.hpp"
#include "firmware/hal/fd_wait.hpp"

namespace tensegrity::fw {
namespace {

// IPv4 only: the end caps and the HIL live on one IPv4 LAN or on loopback.
bool resolve(const UdpEndpoint& endpoint, sockaddr_in& out, std::string& error) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  const int rc = ::getaddrinfo(endpoint.host.c_str(), nullptr, &hints, &found);
  if (rc != 0 || found == nullptr) {
    error = "cannot resolve '" + endpoint.host + "' as IPv4: " + ::gai_strerror(rc);
    return false;
  }
  std::memcpy(&out, found->ai_addr, sizeof(out));
  ::freeaddrinfo(found);
  out.sin_port = htons(endpoint.port);
  return true;
}

}  // namespace

std::unique_ptr<UdpCanBus> UdpCanBus::open(const UdpCanConfig& config, std::string& error) {
  sockaddr_in local{};
  if (!resolve(config.bind, local, error)) {
    error = "udp: bind address: " + error;
    return nullptr;
  }
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    error = std::string("udp: socket() failed: ") + std::strerror(errno);
    return nullptr;
  }
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&local), sizeof(local)) != 0) {
    error = "udp: cannot bind " + config.bind.host + ":" + std::to_string(config.bind.port) +
            ": " + std::strerror(errno);
    ::close(fd);
    return nullptr;
  }
  socklen_t len = sizeof(local);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&local), &len);
  std::unique_ptr<UdpCanBus> bus(new UdpCanBus(fd, ntohs(local.sin_port)));
  if (config.remote.port != 0 && !bus->set_remote(config.remote, error)) return nullptr;
  return bus;
}

UdpCanBus::UdpCanBus(int fd, std::uint16_t local_port) : fd_(fd), local_port_(local_port) {}

UdpCanBus::~UdpCanBus() { ::close(fd_); }

bool UdpCanBus::set_remote(const UdpEndpoint& remote, std::string& error) {
  sockaddr_in addr{};
  if (!resolve(remote, addr, error)) {
    error = "udp: remote address: " + error;
    return false;
  }
  remote_addr_be_ = addr.sin_addr.s_addr;
  remote_port_be_ = addr.sin_port;
  return true;
}

CanResult UdpCanBus::send(const CanFrame& frame) {
  if (!is_valid(frame)) {
    ++counters_.tx_dropped;
    return CanResult::invalid_frame;
  }
  if (counters_.bus_off) {
    ++counters_.tx_dropped;
    return CanResult::bus_off;
  }
  if (remote_port_be_ == 0) {
    ++counters_.tx_dropped;
    last_errno_ = EDESTADDRREQ;
    return CanResult::io_error;
  }
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_addr.s_addr = remote_addr_be_;
  to.sin_port = remote_port_be_;
  const udp_can::Datagram d = udp_can::encode(frame);
  for (;;) {
    const ssize_t n = ::sendto(fd_, d.data(), d.size(), MSG_DONTWAIT,
                               reinterpret_cast<const sockaddr*>(&to), sizeof(to));
    if (n == static_cast<ssize_t>(d.size())) {
      ++counters_.tx_frames;
      return CanResult::ok;
    }
    if (n < 0 && errno == EINTR) continue;
    ++counters_.tx_dropped;
    last_errno_ = n < 0 ? errno : EMSGSIZE;
    return detail::send_error_is_transient(last_errno_) ? CanResult::would_block : CanResult::io_error;
  }
}

CanResult UdpCanBus::receive(CanFrame& frame, std::int64_t timeout_ns) {
  const std::int64_t deadline_ns = detail::receive_deadline_ns(timeout_ns);
  // One byte more than a valid datagram so that an oversized one is seen as such.
  std::array<std::uint8_t, udp_can::kDatagramBytes + 1> buffer{};
  for (;;) {
    const ssize_t n = ::recv(fd_, buffer.data(), buffer.size(), MSG_DONTWAIT | MSG_TRUNC);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK) {
        last_errno_ = errno;
        return CanResult::io_error;
      }
      if (timeout_ns == 0) return CanResult::timeout;
      switch (detail::wait_readable(fd_, deadline_ns)) {
        case detail::WaitResult::ready: continue;
        case detail::WaitResult::timeout: return CanResult::timeout;
        case detail::WaitResult::error: last_errno_ = errno; return CanResult::io_error;
      }
      continue;
    }
    // MSG_TRUNC makes n the datagram's real length even when it did not fit.
    const std::size_t size = static_cast<std::size_t>(n);
    const std::span<const std::uint8_t> bytes(buffer.data(), size < buffer.size() ? size : buffer.size());
    CanFrame got;
    const udp_can::Decoded decoded =
        size > udp_can::kDatagramBytes ? udp_can::Decoded::bad_size : udp_can::decode(bytes, got);
    switch (decoded) {
      case udp_can::Decoded::frame:
        ++counters_.rx_frames;
        frame = got;
        return CanResult::ok;
      case udp_can::Decoded::error_report:
        can_error::apply_error_report(counters_, got.id);
        break;
      default:
        ++counters_.rx_malformed;
        ++drops_[static_cast<std::size_t>(decoded)];
        break;
    }
    // Dropped or absorbed: keep looking until the deadline.
  }
}

}  // namespace tensegrity::fw
