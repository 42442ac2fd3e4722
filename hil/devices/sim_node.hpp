// SPDX-License-Identifier: Apache-2.0
// Emulated CANopen devices (promoted from the driver tests so the HIL emulator and
// the tests share one implementation). They speak only through CanFrames built
// with the same codecs as the master. SimNode is the CiA 301 part every device
// has: NMT state, heartbeat producer, expedited SDO server. Knobs in `script` make
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
    std::int64_t heartbeat_period_ns = 20'000'000;
    bool sdo_silent = false;             // never answer SDO requests
    std::uint32_t sdo_abort_all = 0;     // answer every SDO request with this abort
    bool sdo_segmented_upload = false;   // answer uploads with a segmented-transfer start
    // Stop answering altogether: no heartbeat, no PDOs, no SDO, frames ignored
    // (a device that lost power or its CAN transceiver).
    bool silent = false;
  };

  explicit SimNode(std::uint8_t node_id) : node_id_(node_id) {}
  virtual ~SimNode() = default;

  // Power on: send boot-up, enter pre-operational.
  void boot(std::int64_t now_ns, FrameOut& out);
  void on_frame(const CanFrame& frame, std::int64_t now_ns, FrameOut& out);
  // Time-driven output (heartbeat); call at least once per heartbeat period.
  virtual void tick(std::int64_t now_ns, FrameOut& out);

  std::uint8_t node_id() const { return node_id_; }
  fw::canopen::NmtState nmt_state() const { return nmt_; }
  bool powered() const { return powered_; }
  bool answering() const { return powered_ && !script.silent; }
  Script script;
  std::uint32_t sdo_requests = 0;

 protected:
  // Object dictionary access for SDO; return 0 or an abort code.
  virtual std::uint32_t od_read(fw::canopen::SdoAddress address, std::uint32_t& value, std::uint8_t& size) = 0;
  virtual std::uint32_t od_write(fw::canopen::SdoAddress address, std::uint32_t value, std::uint8_t size) = 0;
  virtual void on_reset_node() {}
  virtual void on_pdo_or_sync(const CanFrame& frame, std::int64_t now_ns, FrameOut& out) = 0;

 private:
  void on_sdo_request(const CanFrame& frame, FrameOut& out);

  std::uint8_t node_id_;
  bool powered_ = false;
  fw::canopen::NmtState nmt_ = fw::canopen::NmtState::unknown;
  std::int64_t next_heartbeat_ns_ = 0;
};

}  // namespace tensegrity::hil
