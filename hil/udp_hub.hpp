// SPDX-License-Identifier: Apache-2.0
// The emulator's side of all twelve end caps' CAN buses: ONE UDP socket on
// 127.0.0.1 that every end cap sends to (its bus spec is
// udp:127.0.0.1:HUB_PORT,bind=127.0.0.1:ITS_PORT), demultiplexed by source port.
// One socket instead of twelve because a lockstep tick then costs one sendmmsg
// for every bus's sensor PDOs and SYNCs and a few recvmmsg for the answers,
// instead of a poll over twelve sockets and a syscall per frame.
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
#include <string>
#include <vector>

#include "firmware/hal/can_frame.hpp"

namespace tensegrity::hil {

struct BusCounters {
  std::uint64_t tx_frames = 0;        // datagrams sent to the end cap
  std::uint64_t rx_frames = 0;        // good frames from the end cap
  std::uint64_t rx_malformed = 0;     // datagrams from it that failed the wire checks
  std::uint64_t injected_drops = 0;   // frames to it dropped on purpose
  std::uint64_t injected_corrupt = 0; // frames to it corrupted on purpose
  std::uint64_t tx_errors = 0;        // sendmmsg refused (buffer full, port closed)
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
  const BusCounters& counters(int endcap) const { return endcaps_[endcap].counters; }
  std::uint64_t rx_unknown_sender() const { return rx_unknown_sender_; }
  std::uint64_t syscalls() const { return syscalls_; }

 private:
  struct Endcap {
    std::uint16_t port = 0;
    double drop_probability = 0.0;
    double corrupt_probability = 0.0;
    CorruptKind corrupt_kind = CorruptKind::frame;
    BusCounters counters;
  };
  struct Pending {
    int endcap;
    std::array<std::uint8_t, 20> bytes;
  };
  int endcap_of_port(std::uint16_t port) const;

  int fd_ = -1;
  std::uint16_t port_ = 0;
  std::vector<Endcap> endcaps_;
  std::vector<Pending> pending_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
  std::uint64_t rx_unknown_sender_ = 0;
  std::uint64_t syscalls_ = 0;
};

}  // namespace tensegrity::hil
