// SPDX-License-Identifier: Apache-2.0
#include "hil/udp_hub.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <ctime>

#include "firmware/drivers/cob_id.hpp"
#include "firmware/hal/udp_can_wire.hpp"
#include "hil/hil_error.hpp"

namespace tensegrity::hil {

std::int64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

namespace {
std::atomic<bool> g_stop{false};
}  // namespace

void request_stop() { g_stop.store(true); }
bool stop_requested() { return g_stop.load(std::memory_order_relaxed); }

namespace {
constexpr std::size_t kBatch = 128;
constexpr std::size_t kRxBytes = fw::udp_can::kDatagramBytes + 1;  // one more: oversize shows

bool is_sync(const fw::CanFrame& f) { return !f.extended && f.id == fw::canopen::kSyncCobId; }
}  // namespace

UdpHub::UdpHub(int endcap_count, std::uint64_t seed) : endcaps_(endcap_count), rng_(seed) {
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw HilError(std::string("HIL hub: socket: ") + std::strerror(errno));
  // Twelve buses' worth of bring-up chatter can arrive between two reads.
  const int buffer_bytes = 4 << 20;
  ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &buffer_bytes, sizeof buffer_bytes);
  ::setsockopt(fd_, SOL_SOCKET, SO_SNDBUF, &buffer_bytes, sizeof buffer_bytes);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd_);
    throw HilError("HIL hub: bind 127.0.0.1:0: " + why);
  }
  socklen_t len = sizeof addr;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
  pending_.reserve(1024);
}

UdpHub::~UdpHub() {
  if (fd_ >= 0) ::close(fd_);
}

void UdpHub::set_endcap_port(int endcap, std::uint16_t port) { endcaps_[endcap].port = port; }

int UdpHub::endcap_of_port(std::uint16_t port) const {
  for (std::size_t e = 0; e < endcaps_.size(); ++e) {
    if (endcaps_[e].port == port) return static_cast<int>(e);
  }
  return -1;
}

void UdpHub::queue(int endcap, const fw::CanFrame& frame) {
  Endcap& e = endcaps_[endcap];
  if (e.port == 0) return;
  fw::CanFrame f = frame;
  bool broken_datagram = false;
  if (!is_sync(frame)) {
    if (e.drop_probability > 0.0 && uniform_(rng_) < e.drop_probability) {
      ++e.counters.injected_drops;
      return;
    }
    if (e.corrupt_probability > 0.0 && uniform_(rng_) < e.corrupt_probability) {
      ++e.counters.injected_corrupt;
      if (e.corrupt_kind == CorruptKind::frame) {
        // Every PDO, heartbeat and SDO of ours has a fixed length; 3 fits none of them.
        f.dlc = 3;
      } else {
        broken_datagram = true;
      }
    }
  }
  Pending p{endcap, fw::udp_can::encode(f)};
  if (broken_datagram) p.bytes[0] ^= 0xFF;  // magic no longer "TCAN"
  pending_.push_back(p);
}

void UdpHub::flush() {
  std::array<mmsghdr, kBatch> msgs{};
  std::array<iovec, kBatch> iov{};
  std::array<sockaddr_in, kBatch> to{};
  std::size_t done = 0;
  while (done < pending_.size()) {
    const std::size_t n = std::min(kBatch, pending_.size() - done);
    for (std::size_t i = 0; i < n; ++i) {
      Pending& p = pending_[done + i];
      to[i] = {};
      to[i].sin_family = AF_INET;
      to[i].sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      to[i].sin_port = htons(endcaps_[p.endcap].port);
      iov[i] = {p.bytes.data(), p.bytes.size()};
      msgs[i] = {};
      msgs[i].msg_hdr.msg_name = &to[i];
      msgs[i].msg_hdr.msg_namelen = sizeof(sockaddr_in);
      msgs[i].msg_hdr.msg_iov = &iov[i];
      msgs[i].msg_hdr.msg_iovlen = 1;
    }
    ++syscalls_;
    const int sent = ::sendmmsg(fd_, msgs.data(), static_cast<unsigned>(n), 0);
    if (sent < 0) {
      if (errno == EINTR) continue;
      // The first message failed (e.g. its end cap's port is closed): count it, skip it.
      ++endcaps_[pending_[done].endcap].counters.tx_errors;
      ++done;
      continue;
    }
    for (int i = 0; i < sent; ++i) ++endcaps_[pending_[done + i].endcap].counters.tx_frames;
    done += static_cast<std::size_t>(sent);
  }
  pending_.clear();
}

std::size_t UdpHub::receive(std::vector<Rx>& out, std::int64_t deadline_ns) {
  std::array<mmsghdr, kBatch> msgs{};
  std::array<iovec, kBatch> iov{};
  std::array<sockaddr_in, kBatch> from{};
  std::array<std::array<std::uint8_t, kRxBytes>, kBatch> buffers{};
  std::size_t appended = 0;
  for (;;) {
    for (std::size_t i = 0; i < kBatch; ++i) {
      iov[i] = {buffers[i].data(), buffers[i].size()};
      msgs[i] = {};
      msgs[i].msg_hdr.msg_name = &from[i];
      msgs[i].msg_hdr.msg_namelen = sizeof(sockaddr_in);
      msgs[i].msg_hdr.msg_iov = &iov[i];
      msgs[i].msg_hdr.msg_iovlen = 1;
    }
    ++syscalls_;
    const int got = ::recvmmsg(fd_, msgs.data(), kBatch, MSG_DONTWAIT, nullptr);
    if (got > 0) {
      for (int i = 0; i < got; ++i) {
        const int e = endcap_of_port(ntohs(from[i].sin_port));
        if (e < 0) {
          ++rx_unknown_sender_;
          continue;
        }
        fw::CanFrame frame;
        const std::size_t size = msgs[i].msg_len;
        const bool truncated = (msgs[i].msg_hdr.msg_flags & MSG_TRUNC) != 0 || size != fw::udp_can::kDatagramBytes;
        if (truncated || fw::udp_can::decode({buffers[i].data(), size}, frame) != fw::udp_can::Decoded::frame) {
          ++endcaps_[e].counters.rx_malformed;
          continue;
        }
        ++endcaps_[e].counters.rx_frames;
        out.push_back({e, frame});
        ++appended;
      }
      if (static_cast<std::size_t>(got) == kBatch) continue;  // maybe more queued
      return appended;
    }
    if (got < 0 && errno == EINTR) continue;
    if (appended > 0 || deadline_ns == 0) return appended;
    const std::int64_t remaining_ns = deadline_ns - monotonic_ns();
    if (remaining_ns <= 0) return 0;
    pollfd pfd{fd_, POLLIN, 0};
    const timespec ts{static_cast<time_t>(remaining_ns / 1'000'000'000), static_cast<long>(remaining_ns % 1'000'000'000)};
    ++syscalls_;
    ::ppoll(&pfd, 1, &ts, nullptr);
  }
}

}  // namespace tensegrity::hil
