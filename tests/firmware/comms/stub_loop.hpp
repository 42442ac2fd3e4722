// SPDX-License-Identifier: Apache-2.0
// A stand-in for firmware/app's control loop, for the DDS tests: the real control
// core (core::EndcapController) with an ideal plant (measured = commanded), driven
// through app::HostLink exactly as ControlLoop drives it, on its own thread.
// Prints "STARTED endcap=E true_ns=T" when a table starts, T being the table's
// time 0 on the machine's real CLOCK_MONOTONIC (the node's clock minus its fake
// offset), so a test can measure the start skew between end caps; likewise
// "ESTOPPED endcap=E true_ns=T" (the cycle that latched an emergency stop) and
// "CLEARED endcap=E true_ns=T" (the cycle that cleared a fault). With
// `stall_commands` it never takes a command from the mailbox (a full queue), but
// still reads the emergency-stop counter every cycle, as ControlLoop does.
#pragma once

#include <atomic>
#include <cstdint>
#include <thread>

#include "firmware/app/host_link.hpp"
#include "core/endcap_controller.hpp"
#include "firmware/hal/clock.hpp"

namespace tensegrity::test {

// CLOCK_MONOTONIC plus a fixed offset: an end cap whose clock disagrees with the host's.
class OffsetClock final : public fw::Clock {
 public:
  explicit OffsetClock(std::int64_t offset_ns) : offset_ns_(offset_ns) {}
  std::int64_t now_ns() const override { return real_.now_ns() + offset_ns_; }
  void sleep_until_ns(std::int64_t deadline_ns) override { real_.sleep_until_ns(deadline_ns - offset_ns_); }
  std::int64_t offset_ns() const { return offset_ns_; }

 private:
  fw::SystemClock real_;
  std::int64_t offset_ns_;
};

class StubLoop {
 public:
  StubLoop(int endcap, fw::app::HostLink& host, OffsetClock& clock, double rate_hz, std::uint32_t motor_count,
           bool stall_commands = false);
  ~StubLoop();
  void start();
  void stop();

 private:
  void run();
  void cycle(std::int64_t loop_ns, double dt_s);
  void apply(const fw::app::HostCommand& command, std::int64_t loop_ns);
  void apply_estops(std::uint32_t estops);
  long long true_now_ns() const { return static_cast<long long>(clock_.now_ns() - clock_.offset_ns()); }

  int endcap_;
  fw::app::HostLink& host_;
  OffsetClock& clock_;
  std::int64_t period_ns_;
  core::EndcapController controller_;
  std::int64_t origin_local_ns_ = 0;  // node clock at loop time 0
  bool pending_start_ = false;
  std::int64_t pending_start_ns_ = 0;
  std::uint32_t ack_sequence_ = 0;
  core::TableError ack_error_ = core::TableError::none;
  std::uint64_t cycles_ = 0;
  std::uint64_t overruns_ = 0;
  bool stall_commands_ = false;
  std::uint32_t estops_seen_ = 0;
  std::uint32_t host_loss_stops_seen_ = 0;
  std::array<double, core::kMaxMotorsPerEndcap> commanded_{};
  std::atomic<bool> running_{false};
  std::thread thread_;
};

}  // namespace tensegrity::test
