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

bool is_loopback(const sockaddr_in& a) { return (ntohl(a.sin_addr.s_addr) >> 24) == 127; }

// A socket bound to loopback cannot reach another host: say how to fix the spec
// instead of failing every send.
bool reachable(bool bound_loopback, const sockaddr_in& remote, const std::string& host, std::string& error) {
  if (!bound_loopback || is_loopback(remote)) return true;
  error = "udp: remote " + host +
          " is not on loopback, and the bus binds 127.0.0.1 unless told: give bind=ADDR:PORT, the local address "
          "facing it";
  return false;
}

}  // namespace

std::unique_ptr<UdpCanBus> UdpCanBus::open(const UdpCanConfig& config, std::string& error) {
  sockaddr_in local{};
  if (!resolve(config.bind, local, error)) {
    error = "udp: bind address: " + error;
    return nullptr;
  }
  const bool bound_loopback = is_loopback(local);
  sockaddr_in remote{};
  if (config.remote.port != 0) {
    if (!resolve(config.remote, remote, error)) {
      error = "udp: remote address: " + error;
      return nullptr;
    }
    if (!reachable(bound_loopback, remote, config.remote.host, error)) return nullptr;
  }
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    error = std::string("udp: socket() failed: ") + std::strerror(errno);
    return nullptr;
  }
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&local), sizeof(local)) != 0) {
    error =
        "udp: cannot bind " + config.bind.host + ":" + std::to_string(config.bind.port) + ": " + std::strerror(errno);
    ::close(fd);
    return nullptr;
  }
  socklen_t len = sizeof(local);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&local), &len);
  std::unique_ptr<UdpCanBus> bus(new UdpCanBus(fd, ntohs(local.sin_port), bound_loopback, config.batch));
  if (config.remote.port != 0 && !bus->set_remote(config.remote, error)) return nullptr;
  return bus;
}

UdpCanBus::UdpCanBus(int fd, std::uint16_t local_port, bool bound_loopback, bool batch)
    : fd_(fd), local_port_(local_port), bound_loopback_(bound_loopback), batch_(batch) {}

UdpCanBus::~UdpCanBus() { ::close(fd_); }

bool UdpCanBus::set_remote(const UdpEndpoint& remote, std::string& error) {
  sockaddr_in addr{};
  if (!resolve(remote, addr, error)) {
    error = "udp: remote address: " + error;
    return false;
  }
  if (!reachable(bound_loopback_, addr, remote.host, error)) return false;
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
  if (!batch_) {
    const udp_can::Datagram d = udp_can::encode(frame);
    return send_bytes(d, 1);
  }
  // Full: the queued frames go now, so a long burst (bring-up) is never refused.
  if (tx_batch_.full()) (void)flush();
  tx_batch_.add(frame);
  return CanResult::ok;
}

CanResult UdpCanBus::flush() {
  if (tx_batch_.empty()) return CanResult::ok;
  const CanResult r = send_bytes(tx_batch_.bytes(), tx_batch_.count());
  tx_batch_.clear();
  return r;
}

CanResult UdpCanBus::send_bytes(std::span<const std::uint8_t> bytes, std::size_t frames) {
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_addr.s_addr = remote_addr_be_;
  to.sin_port = remote_port_be_;
  for (;;) {
    const ssize_t n =
        ::sendto(fd_, bytes.data(), bytes.size(), MSG_DONTWAIT, reinterpret_cast<const sockaddr*>(&to), sizeof(to));
    if (n == static_cast<ssize_t>(bytes.size())) {
      counters_.tx_frames += frames;
      return CanResult::ok;
    }
    if (n < 0 && errno == EINTR) continue;
    counters_.tx_dropped += frames;
    last_errno_ = n < 0 ? errno : EMSGSIZE;
    return detail::send_error_is_transient(last_errno_) ? CanResult::would_block : CanResult::io_error;
  }
}

// Frames go to the queue receive() hands out; error reports to the counters;
// whatever fails the checks is counted by reason.
void UdpCanBus::take_datagram(std::span<const std::uint8_t> datagram) {
  const udp_can::DatagramReader reader(datagram);
  if (reader.status() != udp_can::Decoded::frame) {
    ++counters_.rx_malformed;
    ++drops_[static_cast<std::size_t>(reader.status())];
    return;
  }
  rx_next_ = 0;
  rx_count_ = 0;
  for (std::size_t i = 0; i < reader.count(); ++i) {
    CanFrame got;
    const udp_can::Decoded decoded = reader.read(i, got);
    switch (decoded) {
      case udp_can::Decoded::frame:
        ++counters_.rx_frames;
        rx_queue_[rx_count_++] = got;
        break;
      case udp_can::Decoded::error_report: can_error::apply_error_report(counters_, got.id); break;
      default:
        ++counters_.rx_malformed;
        ++drops_[static_cast<std::size_t>(decoded)];
        break;
    }
  }
}

CanResult UdpCanBus::receive(CanFrame& frame, std::int64_t timeout_ns) {
  const std::int64_t deadline_ns = detail::receive_deadline_ns(timeout_ns);
  // One byte more than the largest valid datagram so that an oversized one is seen as such.
  std::array<std::uint8_t, udp_can::kMaxDatagramBytes + 1> buffer;
  for (;;) {
    if (rx_next_ < rx_count_) {
      frame = rx_queue_[rx_next_++];
      return CanResult::ok;
    }
    // A caller prepared to wait has usually drained the socket already (a lockstep
    // end cap between two SYNCs): wait first, then read, saving a recv() that
    // would only say EAGAIN.
    if (timeout_ns != 0) {
      switch (detail::wait_readable(fd_, deadline_ns)) {
        case detail::WaitResult::ready: break;
        case detail::WaitResult::timeout: return CanResult::timeout;
        case detail::WaitResult::error: last_errno_ = errno; return CanResult::io_error;
      }
    }
    sockaddr_in from{};
    socklen_t from_len = sizeof(from);
    const ssize_t n = ::recvfrom(fd_, buffer.data(), buffer.size(), MSG_DONTWAIT | MSG_TRUNC,
                                 reinterpret_cast<sockaddr*>(&from), &from_len);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK) {
        last_errno_ = errno;
        return CanResult::io_error;
      }
      if (timeout_ns == 0) return CanResult::timeout;
      continue;  // woken without a datagram: wait again
    }
    // Only the peer's frames are the bus's (before a remote is set, nobody's).
    if (remote_port_be_ == 0 || from.sin_port != remote_port_be_ || from.sin_addr.s_addr != remote_addr_be_) {
      ++counters_.rx_unknown_sender;
      continue;
    }
    // MSG_TRUNC makes n the datagram's real length even when it did not fit.
    const auto size = static_cast<std::size_t>(n);
    if (size > udp_can::kMaxDatagramBytes) {
      ++counters_.rx_malformed;
      ++drops_[static_cast<std::size_t>(udp_can::Decoded::bad_size)];
      continue;
    }
    take_datagram({buffer.data(), size});
    // Dropped or absorbed frames: keep looking until the deadline.
  }
}

}  // namespace tensegrity::fw
