// SPDX-License-Identifier: Apache-2.0
#include "hil/udp_hub.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>

#include "firmware/drivers/cob_id.hpp"
#include "firmware/hal/udp_can_wire.hpp"
#include "hil/clock.hpp"
#include "hil/hil_error.hpp"

namespace tensegrity::hil {

namespace {
constexpr std::size_t kBatch = 64;  // datagrams per sendmmsg / recvmmsg

bool is_sync(const fw::CanFrame& f) { return !f.extended && f.id == fw::canopen::kSyncCobId; }

// The kernel stamps datagrams with CLOCK_REALTIME; their age now, taken from the
// monotonic clock now, gives the monotonic arrival time without trusting the
// offset between the two clocks beyond this instant.
std::int64_t newest_arrival_ns(mmsghdr* msgs, std::size_t count) {
  timespec real{};
  clock_gettime(CLOCK_REALTIME, &real);
  const std::int64_t mono = monotonic_ns();
  const std::int64_t real_ns = static_cast<std::int64_t>(real.tv_sec) * 1'000'000'000 + real.tv_nsec;
  std::int64_t latest = 0;
  for (std::size_t i = 0; i < count; ++i) {
    msghdr& h = msgs[i].msg_hdr;
    for (cmsghdr* c = CMSG_FIRSTHDR(&h); c != nullptr; c = CMSG_NXTHDR(&h, c)) {
      if (c->cmsg_level != SOL_SOCKET || c->cmsg_type != SCM_TIMESTAMPNS) continue;
      timespec ts{};
      std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
      const std::int64_t age = real_ns - (static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec);
      latest = std::max(latest, mono - std::max<std::int64_t>(age, 0));
    }
  }
  return latest;
}
}  // namespace

UdpHub::UdpHub(int endcap_count, std::uint64_t seed) : endcaps_(endcap_count), rng_(seed) {
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw HilError(std::string("HIL hub: socket: ") + std::strerror(errno));
  // Twelve buses' worth of bring-up chatter can arrive between two reads.
  const int buffer_bytes = 4 << 20;
  ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &buffer_bytes, sizeof buffer_bytes);
  ::setsockopt(fd_, SOL_SOCKET, SO_SNDBUF, &buffer_bytes, sizeof buffer_bytes);
  const int on = 1;
  ::setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);  // latest_arrival_ns()
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
  outgoing_.resize(static_cast<std::size_t>(endcap_count) * 2);
  open_batch_.assign(static_cast<std::size_t>(endcap_count), -1);
  rx_buffers_.resize(kBatch);
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
  pending_.push_back({endcap, f, broken_datagram});
}

void UdpHub::flush() {
  // Group the frames into datagrams, each end cap's in queue order: one batch per
  // end cap that reads version 2 (more if it overflows), else one datagram each.
  std::size_t used = 0;
  const auto next_outgoing = [&]() -> Outgoing& {
    if (used == outgoing_.size()) outgoing_.emplace_back();
    Outgoing& o = outgoing_[used++];
    o.writer.clear();
    return o;
  };
  for (const Pending& p : pending_) {
    if (p.broken || !endcaps_[p.endcap].batches) {
      Outgoing& o = next_outgoing();
      o.endcap = p.endcap;
      o.batch = false;
      o.single = fw::udp_can::encode(p.frame);
      if (p.broken) o.single[0] ^= 0xFF;  // magic no longer "TCAN"
      continue;
    }
    int& open = open_batch_[p.endcap];
    if (open < 0 || outgoing_[open].writer.full()) {
      Outgoing& o = next_outgoing();
      o.endcap = p.endcap;
      o.batch = true;
      open = static_cast<int>(used - 1);
    }
    outgoing_[open].writer.add(p.frame);
  }
  pending_.clear();
  std::fill(open_batch_.begin(), open_batch_.end(), -1);

  std::array<mmsghdr, kBatch> msgs{};
  std::array<iovec, kBatch> iov{};
  std::array<sockaddr_in, kBatch> to{};
  std::size_t done = 0;
  while (done < used) {
    const std::size_t n = std::min(kBatch, used - done);
    for (std::size_t i = 0; i < n; ++i) {
      Outgoing& o = outgoing_[done + i];
      to[i] = {};
      to[i].sin_family = AF_INET;
      to[i].sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      to[i].sin_port = htons(endcaps_[o.endcap].port);
      const std::span<const std::uint8_t> bytes =
          o.batch ? o.writer.bytes() : std::span<const std::uint8_t>(o.single.data(), o.single.size());
      iov[i] = {const_cast<std::uint8_t*>(bytes.data()), bytes.size()};
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
      endcaps_[outgoing_[done].endcap].counters.tx_errors += outgoing_[done].frames();
      ++done;
      continue;
    }
    for (int i = 0; i < sent; ++i) {
      BusCounters& c = endcaps_[outgoing_[done + i].endcap].counters;
      c.tx_frames += outgoing_[done + i].frames();
      ++c.tx_datagrams;
    }
    done += static_cast<std::size_t>(sent);
  }
}

void UdpHub::take_datagram(int e, std::span<const std::uint8_t> datagram, std::vector<Rx>& out, std::size_t& appended) {
  Endcap& ec = endcaps_[e];
  ++ec.counters.rx_datagrams;
  const fw::udp_can::DatagramReader reader(datagram);
  if (reader.status() != fw::udp_can::Decoded::frame) {
    ++ec.counters.rx_malformed;
    return;
  }
  if (reader.version() == fw::udp_can::kBatchVersion) ec.batches = true;
  for (std::size_t i = 0; i < reader.count(); ++i) {
    fw::CanFrame frame;
    // End caps send no error reports: anything but a frame is malformed here.
    if (reader.read(i, frame) != fw::udp_can::Decoded::frame) {
      ++ec.counters.rx_malformed;
      continue;
    }
    ++ec.counters.rx_frames;
    out.push_back({e, frame});
    ++appended;
  }
}

std::size_t UdpHub::receive(std::vector<Rx>& out, std::int64_t deadline_ns) {
  std::array<mmsghdr, kBatch> msgs{};
  std::array<iovec, kBatch> iov{};
  std::array<sockaddr_in, kBatch> from{};
  std::array<Control, kBatch> control;
  std::size_t appended = 0;
  // A caller that may wait has usually just drained the socket (the barrier right
  // after a SYNC): wait first, then read, saving a recvmmsg that says EAGAIN.
  bool wait_first = deadline_ns != 0;
  for (;;) {
    if (wait_first) {
      wait_first = false;
      const std::int64_t remaining_ns = deadline_ns - monotonic_ns();
      if (remaining_ns > 0) {
        pollfd pfd{fd_, POLLIN, 0};
        const timespec ts{static_cast<time_t>(remaining_ns / 1'000'000'000),
                          static_cast<long>(remaining_ns % 1'000'000'000)};
        ++syscalls_;
        ::ppoll(&pfd, 1, &ts, nullptr);
      }
    }
    for (std::size_t i = 0; i < kBatch; ++i) {
      iov[i] = {rx_buffers_[i].data(), rx_buffers_[i].size()};
      msgs[i] = {};
      msgs[i].msg_hdr.msg_name = &from[i];
      msgs[i].msg_hdr.msg_namelen = sizeof(sockaddr_in);
      msgs[i].msg_hdr.msg_iov = &iov[i];
      msgs[i].msg_hdr.msg_iovlen = 1;
      msgs[i].msg_hdr.msg_control = control[i].bytes;
      msgs[i].msg_hdr.msg_controllen = sizeof control[i].bytes;
    }
    ++syscalls_;
    const int got = ::recvmmsg(fd_, msgs.data(), kBatch, MSG_DONTWAIT, nullptr);
    if (got > 0) {
      latest_arrival_ns_ = std::max(latest_arrival_ns_, newest_arrival_ns(msgs.data(), static_cast<std::size_t>(got)));
      for (int i = 0; i < got; ++i) {
        const int e = endcap_of_port(ntohs(from[i].sin_port));
        if (e < 0) {
          ++rx_unknown_sender_;
          continue;
        }
        const std::size_t size = msgs[i].msg_len;
        if ((msgs[i].msg_hdr.msg_flags & MSG_TRUNC) != 0 || size > fw::udp_can::kMaxDatagramBytes) {
          ++endcaps_[e].counters.rx_datagrams;
          ++endcaps_[e].counters.rx_malformed;
          continue;
        }
        take_datagram(e, {rx_buffers_[i].data(), size}, out, appended);
      }
      if (static_cast<std::size_t>(got) == kBatch) continue;  // maybe more queued
      return appended;
    }
    if (got < 0 && errno == EINTR) continue;
    if (appended > 0 || deadline_ns == 0 || monotonic_ns() >= deadline_ns) return appended;
    wait_first = true;  // woken without a datagram (a signal): wait again
  }
}

}  // namespace tensegrity::hil
