// SPDX-License-Identifier: Apache-2.0
#include "firmware/hal/socketcan_bus.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include "firmware/hal/can_error.hpp"
#include "firmware/hal/fd_wait.hpp"

namespace tensegrity::fw {

static_assert(can_error::kBusOff == CAN_ERR_BUSOFF && can_error::kRestarted == CAN_ERR_RESTARTED &&
                  can_error::kController == CAN_ERR_CRTL,
              "can_error.hpp must mirror linux/can/error.h");

std::unique_ptr<SocketCanBus> SocketCanBus::open(const std::string& interface_name, std::string& error) {
  const int fd = ::socket(AF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    const int e = errno;
    error = e == EAFNOSUPPORT
                ? std::string("socketcan: kernel has no CAN support (socket(AF_CAN) failed: ") + std::strerror(e) + ")"
                : std::string("socketcan: socket(AF_CAN) failed: ") + std::strerror(e);
    return nullptr;
  }
  const unsigned index = ::if_nametoindex(interface_name.c_str());
  if (index == 0) {
    error = "socketcan: no interface '" + interface_name + "' (" + std::strerror(errno) +
            "); for a virtual bus: ip link add dev " + interface_name + " type vcan && ip link set " + interface_name +
            " up";
    ::close(fd);
    return nullptr;
  }
  const can_err_mask_t err_mask = CAN_ERR_MASK;
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof(err_mask)) != 0) {
    error = std::string("socketcan: cannot enable error frames: ") + std::strerror(errno);
    ::close(fd);
    return nullptr;
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(index);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) != 0) {
    error = "socketcan: cannot bind to '" + interface_name + "': " + std::strerror(errno);
    ::close(fd);
    return nullptr;
  }
  return std::unique_ptr<SocketCanBus>(new SocketCanBus(fd, interface_name));
}

SocketCanBus::SocketCanBus(int fd, std::string interface_name) : fd_(fd), interface_name_(std::move(interface_name)) {}

SocketCanBus::~SocketCanBus() { ::close(fd_); }

CanResult SocketCanBus::set_filters(std::span<const CanIdFilter> filters) {
  std::vector<can_filter> kernel_filters;
  kernel_filters.reserve(filters.size());
  for (const CanIdFilter& f : filters) {
    can_filter k{};
    // EFF and RTR in the mask make an 11-bit filter ignore 29-bit frames and RTRs.
    k.can_id = f.extended ? (f.id & CAN_EFF_MASK) | CAN_EFF_FLAG : f.id & CAN_SFF_MASK;
    k.can_mask = (f.extended ? f.mask & CAN_EFF_MASK : f.mask & CAN_SFF_MASK) | CAN_EFF_FLAG | CAN_RTR_FLAG;
    kernel_filters.push_back(k);
  }
  const auto bytes = static_cast<socklen_t>(kernel_filters.size() * sizeof(can_filter));
  if (::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, kernel_filters.empty() ? nullptr : kernel_filters.data(), bytes) !=
      0) {
    last_errno_ = errno;
    return CanResult::io_error;
  }
  return CanResult::ok;
}

CanResult SocketCanBus::send(const CanFrame& frame) {
  if (!is_valid(frame)) {
    ++counters_.tx_dropped;
    return CanResult::invalid_frame;
  }
  if (counters_.bus_off) {
    ++counters_.tx_dropped;
    return CanResult::bus_off;
  }
  can_frame k{};
  k.can_id = frame.id | (frame.extended ? CAN_EFF_FLAG : 0U) | (frame.rtr ? CAN_RTR_FLAG : 0U);
  k.can_dlc = frame.dlc;
  if (!frame.rtr) std::memcpy(k.data, frame.data.data(), frame.dlc);
  for (;;) {
    const ssize_t n = ::write(fd_, &k, sizeof(k));
    if (n == static_cast<ssize_t>(sizeof(k))) {
      ++counters_.tx_frames;
      return CanResult::ok;
    }
    if (n < 0 && errno == EINTR) continue;
    ++counters_.tx_dropped;
    last_errno_ = n < 0 ? errno : EIO;
    return detail::send_error_is_transient(last_errno_) ? CanResult::would_block : CanResult::io_error;
  }
}

CanResult SocketCanBus::receive(CanFrame& frame, std::int64_t timeout_ns) {
  const std::int64_t deadline_ns = detail::receive_deadline_ns(timeout_ns);
  for (;;) {
    can_frame k{};
    const ssize_t n = ::read(fd_, &k, sizeof(k));
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
    if (n != static_cast<ssize_t>(sizeof(k)) || k.can_dlc > CAN_MAX_DLEN) {
      ++counters_.rx_malformed;
      continue;
    }
    if ((k.can_id & CAN_ERR_FLAG) != 0) {
      can_error::apply_error_report(counters_, k.can_id & CAN_ERR_MASK);
      continue;
    }
    CanFrame f;
    f.extended = (k.can_id & CAN_EFF_FLAG) != 0;
    f.rtr = (k.can_id & CAN_RTR_FLAG) != 0;
    f.id = k.can_id & (f.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
    f.dlc = k.can_dlc;
    if (!f.rtr) std::memcpy(f.data.data(), k.data, k.can_dlc);
    ++counters_.rx_frames;
    frame = f;
    return CanResult::ok;
  }
}

}  // namespace tensegrity::fw
