// SPDX-License-Identifier: Apache-2.0
// CanBus over UDP, for kernels without AF_CAN and for the HIL emulator. Wire format:
// udp_can_wire.hpp (version 1, one frame a datagram), udp_can_batch.hpp (version 2,
// several) and docs/design/udp-can.md. The socket is unconnected: frames are sent to the
// configured remote and accepted from any sender, so an emulator may answer from
// whichever socket it likes. Both versions are always read; with `batch` the frames
// send() is given wait for flush() (the control loop's end of cycle) and go out as
// one version-2 datagram.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "firmware/hal/can_bus.hpp"
#include "firmware/hal/can_bus_spec.hpp"
#include "firmware/hal/udp_can_batch.hpp"
#include "firmware/hal/udp_can_wire.hpp"

namespace tensegrity::fw {

struct UdpCanConfig {
  UdpEndpoint remote;  // where send() goes and the only sender taken; port 0 = not yet known (set_remote later)
  UdpEndpoint bind;    // local address (default loopback); port 0 = any free port (see local_port())
  bool batch = false;  // send version 2, one datagram per flush(): only to a peer that reads it
};

class UdpCanBus final : public CanBus {
 public:
  // nullptr and a one-line reason in `error` when the socket cannot be made, or
  // when a remote off loopback is given without a bind address facing it.
  static std::unique_ptr<UdpCanBus> open(const UdpCanConfig& config, std::string& error);
  ~UdpCanBus() override;
  UdpCanBus(const UdpCanBus&) = delete;
  UdpCanBus& operator=(const UdpCanBus&) = delete;

  CanResult send(const CanFrame& frame) override;
  CanResult receive(CanFrame& frame, std::int64_t timeout_ns) override;
  // Batch mode: sends what send() queued as one datagram. A failure drops those
  // frames (counted in tx_dropped). Otherwise nothing to do.
  CanResult flush() override;
  CanCounters counters() const override { return counters_; }

  // Until a remote is set, every datagram is dropped (no sender is known).
  bool set_remote(const UdpEndpoint& remote, std::string& error);
  std::uint16_t local_port() const { return local_port_; }
  // Datagrams dropped for `reason` (frame and error_report count as received).
  std::uint64_t dropped(udp_can::Decoded reason) const { return drops_[static_cast<std::size_t>(reason)]; }
  int last_errno() const { return last_errno_; }

 private:
  UdpCanBus(int fd, std::uint16_t local_port, bool bound_loopback, bool batch);
  CanResult send_bytes(std::span<const std::uint8_t> bytes, std::size_t frames);
  void take_datagram(std::span<const std::uint8_t> datagram);

  int fd_;
  std::uint16_t local_port_;
  bool bound_loopback_;
  std::uint32_t remote_addr_be_ = 0;  // network byte order, as sockaddr_in wants
  std::uint16_t remote_port_be_ = 0;
  CanCounters counters_;
  std::array<std::uint64_t, udp_can::kDecodedCount> drops_{};
  int last_errno_ = 0;
  bool batch_;
  udp_can::BatchWriter tx_batch_;
  // Frames of the last datagram read, handed out one per receive().
  std::array<CanFrame, udp_can::kMaxBatchFrames> rx_queue_{};
  std::size_t rx_next_ = 0, rx_count_ = 0;
};

}  // namespace tensegrity::fw
