// SPDX-License-Identifier: Apache-2.0
// Emulated CANopen devices (promoted from the driver tests so the HIL emulator and
// the tests share one implementation). They speak only through CanFrames built
// with the same codecs as the master. SimNode is the CiA 301 part every device
// has: NMT state, heartbeat producer and consumer (0x1016: it watches one other
// node, the end cap, and reacts when that falls silent), expedited SDO server,
// reboot. Knobs in `script` make
// a device misbehave on purpose (fault injection at the device boundary).
#pragma once

#include <cstdint>
#include <vector>

#include "firmware/drivers/nmt.hpp"
#include "firmware/drivers/sdo_codec.hpp"
#include "firmware/hal/can_frame.hpp"

namespace tensegrity::hil {

namespace canopen = fw::canopen;
using fw::CanFrame;
using FrameOut = std::vector<CanFrame>;

class SimNode {
 public:
  struct Script {
    bool heartbeat = true;
    // The factory default of 0x1017: the period the device beats at after power-on
    // or a reset, until the master writes its own (0 ms: no heartbeat).
    std::int64_t heartbeat_period_ns = 20'000'000;
    bool sdo_silent = false;            // never answer SDO requests
    std::uint32_t sdo_abort_all = 0;    // answer every SDO request with this abort
    bool sdo_segmented_upload = false;  // answer uploads with a segmented-transfer start
    // Stop answering altogether: no heartbeat, no PDOs, no SDO, frames ignored
    // (a device that lost power or its CAN transceiver).
    bool silent = false;
  };

  explicit SimNode(std::uint8_t node_id) : node_id_(node_id) {}
  virtual ~SimNode() = default;

  // Power on: send boot-up, enter pre-operational. The communication objects
  // (0x1016, 0x1017) are back at their power-on values: not configured.
  void boot(std::int64_t now_ns, FrameOut& out);
  // A power cycle (brown-out, watchdog reset): application state reset, then boot.
  void reboot(std::int64_t now_ns, FrameOut& out);
  void on_frame(const CanFrame& frame, std::int64_t now_ns, FrameOut& out);
  // Time-driven output (heartbeat); call at least once per heartbeat period.
  virtual void tick(std::int64_t now_ns, FrameOut& out);
  // Fault injection: the device leaves NMT operational by itself (its own
  // firmware's error reaction, a local operator) and goes on beating in `state`
  // (pre-operational or stopped): no PDOs in or out, unlike a reboot no boot-up.
  void leave_operational(fw::canopen::NmtState state);

  std::uint8_t node_id() const { return node_id_; }
  fw::canopen::NmtState nmt_state() const { return nmt_; }
  bool powered() const { return powered_; }
  bool answering() const { return powered_ && !script.silent; }
  Script script;
  std::uint32_t sdo_requests = 0;

  // Heartbeat consumer (one entry of 0x1016): 0 ms is unused. Monitoring starts
  // with the first heartbeat heard after configuration (CiA 301); a timeout
  // reacts once (on_heartbeat_lost) and monitoring waits for the next heartbeat.
  std::uint8_t consumer_node() const { return consumer_node_; }
  std::uint16_t consumer_time_ms() const { return consumer_time_ms_; }
  bool consumer_armed() const { return consumer_armed_; }
  std::int64_t last_consumed_heartbeat_ns() const { return last_consumed_ns_; }
  std::int64_t heartbeat_lost_ns() const { return heartbeat_lost_ns_; }  // last timeout (device time)
  std::uint32_t heartbeat_losses() const { return heartbeat_losses_; }
  std::uint32_t reboots() const { return reboots_; }
  // 0x1017 as it stands (the factory default until written): the producer period.
  std::int64_t heartbeat_period_ns() const { return heartbeat_period_ns_; }

 protected:
  // Object dictionary access for SDO; return 0 or an abort code.
  virtual std::uint32_t od_read(fw::canopen::SdoAddress address, std::uint32_t& value, std::uint8_t& size) = 0;
  virtual std::uint32_t od_write(fw::canopen::SdoAddress address, std::uint32_t value, std::uint8_t size) = 0;
  virtual void on_reset_node() {}
  // The consumed heartbeat timed out: the device's own reaction (a drive: 0x6007).
  virtual void on_heartbeat_lost(std::int64_t /*now_ns*/, FrameOut& /*out*/) {}
  // Time stood still for this device (the HIL's start gate): monitoring restarts
  // from the next tick instead of counting the pause as silence.
  void restart_consumer_timer() { consumer_restart_ = true; }
  virtual void on_pdo_or_sync(const CanFrame& frame, std::int64_t now_ns, FrameOut& out) = 0;

 private:
  void on_sdo_request(const CanFrame& frame, FrameOut& out);
  bool consume_heartbeat(const CanFrame& frame, std::int64_t now_ns);
  // 0x1016 / 0x1017, shared by every device; true when `address` is one of them.
  bool comm_od_read(fw::canopen::SdoAddress address, std::uint32_t& value, std::uint8_t& size, std::uint32_t& abort);
  bool comm_od_write(fw::canopen::SdoAddress address, std::uint32_t value, std::uint8_t size, std::uint32_t& abort);

  std::uint8_t node_id_;
  bool powered_ = false;
  fw::canopen::NmtState nmt_ = fw::canopen::NmtState::unknown;
  std::int64_t next_heartbeat_ns_ = 0;
  std::int64_t heartbeat_period_ns_ = 0;
  std::uint8_t consumer_node_ = 0;
  std::uint16_t consumer_time_ms_ = 0;
  bool consumer_armed_ = false;
  bool consumer_restart_ = false;
  std::int64_t last_consumed_ns_ = 0;
  std::int64_t heartbeat_lost_ns_ = -1;
  std::uint32_t heartbeat_losses_ = 0;
  std::uint32_t reboots_ = 0;
};

}  // namespace tensegrity::hil
