// SPDX-License-Identifier: Apache-2.0
// The emulator's side of all twelve end caps' CAN buses: ONE UDP socket on
// 127.0.0.1 that every end cap sends to (its bus spec is
// udp:127.0.0.1:HUB_PORT,bind=127.0.0.1:ITS_PORT,batch), demultiplexed by source port.
// One socket instead of twelve because a lockstep tick then costs one sendmmsg
// for every bus's sensor PDOs and SYNCs and a few recvmmsg for the answers,
// instead of a poll over twelve sockets and a syscall per frame.
//
// Datagram versions (docs/design/udp-can.md): the hub reads both, and answers an end cap
// in version 2 (all of a flush's frames to it in one datagram) once that end cap
// has sent version 2 itself, so an end cap that only knows version 1 still works.
// One datagram per end cap and tick matters more than the syscall count: every
// datagram is a trip through the loopback stack and may wake the end cap.
//
// Fault injection on the wire lives here: dropped and corrupted frames towards
// one end cap. SYNC is never dropped or corrupted: in lockstep it is the tick
// itself, and losing it would stall the barrier (a real CAN bus retransmits a
// frame that failed its CRC; what gets lost is the content, modelled here).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "firmware/hal/can_frame.hpp"
#include "firmware/hal/udp_can_batch.hpp"

namespace tensegrity::hil {

struct BusCounters {
  std::uint64_t tx_frames = 0;         // datagrams sent to the end cap
  std::uint64_t rx_frames = 0;         // good frames from the end cap
  std::uint64_t rx_malformed = 0;      // datagrams from it that failed the wire checks
  std::uint64_t injected_drops = 0;    // frames to it dropped on purpose
  std::uint64_t injected_corrupt = 0;  // frames to it corrupted on purpose
  std::uint64_t tx_errors = 0;         // frames sendmmsg refused (buffer full, port closed)
  std::uint64_t tx_datagrams = 0;      // datagrams those frames travelled in
  std::uint64_t rx_datagrams = 0;      // datagrams from the end cap
};

enum class CorruptKind : std::uint8_t {
  frame,     // a well-formed datagram carrying a frame of the wrong length: the master rejects it
  datagram,  // a broken datagram (bad magic): the end cap's UDP layer rejects it
};

class UdpHub {
 public:
  struct Rx {
    int endcap = -1;
    fw::CanFrame frame;
  };

  // Binds 127.0.0.1:0; throws HilError.
  UdpHub(int endcap_count, std::uint64_t seed = 1);
  ~UdpHub();
  UdpHub(const UdpHub&) = delete;
  UdpHub& operator=(const UdpHub&) = delete;

  std::uint16_t port() const { return port_; }
  int endcap_count() const { return static_cast<int>(endcaps_.size()); }
  void set_endcap_port(int endcap, std::uint16_t port);
  std::uint16_t endcap_port(int endcap) const { return endcaps_[endcap].port; }

  // Queued frames go out in flush(), in order, batched.
  void queue(int endcap, const fw::CanFrame& frame);
  void flush();
  // Appends received frames to `out`; waits until CLOCK_MONOTONIC `deadline_ns`
  // for the first one (0: do not wait). Returns how many were appended.
  std::size_t receive(std::vector<Rx>& out, std::int64_t deadline_ns);

  void set_drop(int endcap, double probability) { endcaps_[endcap].drop_probability = probability; }
  void set_corrupt(int endcap, double probability, CorruptKind kind) {
    endcaps_[endcap].corrupt_probability = probability;
    endcaps_[endcap].corrupt_kind = kind;
  }
  // A new process on the end cap's port may not read version 2: talk version 1
  // until it sends version 2 itself.
  void forget_version(int endcap) { endcaps_[endcap].batches = false; }
  bool batches(int endcap) const { return endcaps_[endcap].batches; }
  const BusCounters& counters(int endcap) const { return endcaps_[endcap].counters; }
  // CLOCK_MONOTONIC time at which the kernel received the latest datagram read
  // since the last reset (SO_TIMESTAMPNS); 0 if none. Tells the stepper when the
  // end caps answered, whenever it happened to look.
  std::int64_t latest_arrival_ns() const { return latest_arrival_ns_; }
  void reset_latest_arrival() { latest_arrival_ns_ = 0; }
  std::uint64_t rx_unknown_sender() const { return rx_unknown_sender_; }
  std::uint64_t syscalls() const { return syscalls_; }

 private:
  struct Endcap {
    std::uint16_t port = 0;
    bool batches = false;  // it sent version 2: it reads it
    double drop_probability = 0.0;
    double corrupt_probability = 0.0;
    CorruptKind corrupt_kind = CorruptKind::frame;
    BusCounters counters;
  };
  struct Pending {
    int endcap;
    fw::CanFrame frame;
    bool broken;  // to go out alone, as a version-1 datagram with a bad magic
  };
  // One datagram of a flush: a batch, or a single version-1 frame.
  struct Outgoing {
    int endcap = -1;
    bool batch = false;
    fw::udp_can::BatchWriter writer;
    fw::udp_can::Datagram single{};
    std::size_t frames() const { return batch ? writer.count() : 1; }
  };
  using RxBuffer = std::array<std::uint8_t, fw::udp_can::kMaxDatagramBytes + 1>;  // one more: oversize shows
  struct Control {                                                                // room for one SCM_TIMESTAMPNS
    alignas(8) char bytes[64];
  };
  void take_datagram(int endcap, std::span<const std::uint8_t> datagram, std::vector<Rx>& out, std::size_t& appended);
  int endcap_of_port(std::uint16_t port) const;

  int fd_ = -1;
  std::uint16_t port_ = 0;
  std::vector<Endcap> endcaps_;
  std::vector<Pending> pending_;
  std::vector<Outgoing> outgoing_;    // reused by flush(); grows, never shrinks
  std::vector<int> open_batch_;       // per end cap: its batch in outgoing_, -1 none
  std::vector<RxBuffer> rx_buffers_;  // recvmmsg's buffers, made once
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
  std::uint64_t rx_unknown_sender_ = 0;
  std::int64_t latest_arrival_ns_ = 0;
  std::uint64_t syscalls_ = 0;
};

}  // namespace tensegrity::hil
