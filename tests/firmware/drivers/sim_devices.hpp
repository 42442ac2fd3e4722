// SPDX-License-Identifier: Apache-2.0
// Scripted CANopen devices for tests: a CiA 402 drive in cyclic synchronous
// position mode and a two-channel load cell. They speak only through CanFrames,
// built with the same codecs as the master, so the HIL emulator may adopt them.
// Knobs in `script` make them misbehave on purpose.
#pragma once

#include <cstdint>
#include <vector>

#include "firmware/drivers/cia402.hpp"
#include "firmware/drivers/nmt.hpp"
#include "firmware/drivers/pdo_codec.hpp"
#include "firmware/drivers/sdo_codec.hpp"
#include "firmware/hal/can_frame.hpp"

namespace tensegrity::fw::sim {

using FrameOut = std::vector<CanFrame>;

// NMT, heartbeat and SDO-server behaviour shared by both devices.
class SimNode {
 public:
  struct Script {
    bool heartbeat = true;
    std::int64_t heartbeat_period_ns = 20'000'000;
    bool sdo_silent = false;             // never answer SDO requests
    std::uint32_t sdo_abort_all = 0;     // answer every SDO request with this abort
    bool sdo_segmented_upload = false;   // answer uploads with a segmented-transfer start
  };

  explicit SimNode(std::uint8_t node_id) : node_id_(node_id) {}
  virtual ~SimNode() = default;

  // Power on: send boot-up, enter pre-operational.
  void boot(std::int64_t now_ns, FrameOut& out);
  void on_frame(const CanFrame& frame, std::int64_t now_ns, FrameOut& out);
  virtual void tick(std::int64_t now_ns, FrameOut& out);

  std::uint8_t node_id() const { return node_id_; }
  canopen::NmtState nmt_state() const { return nmt_; }
  bool powered() const { return powered_; }
  Script script;
  std::uint32_t sdo_requests = 0;

 protected:
  // Object dictionary access for SDO; return 0 or an abort code.
  virtual std::uint32_t od_read(canopen::SdoAddress address, std::uint32_t& value, std::uint8_t& size) = 0;
  virtual std::uint32_t od_write(canopen::SdoAddress address, std::uint32_t value, std::uint8_t size) = 0;
  virtual void on_reset_node() {}
  virtual void on_pdo_or_sync(const CanFrame& frame, std::int64_t now_ns, FrameOut& out) = 0;

 private:
  void on_sdo_request(const CanFrame& frame, FrameOut& out);

  std::uint8_t node_id_;
  bool powered_ = false;
  canopen::NmtState nmt_ = canopen::NmtState::unknown;
  std::int64_t next_heartbeat_ns_ = 0;
};

class SimCia402Drive final : public SimNode {
 public:
  explicit SimCia402Drive(std::uint8_t node_id) : SimNode(node_id) {}

  // Enters fault reaction (EMCY sent now), then fault on the next tick.
  void inject_fault(std::uint16_t error_code, std::int64_t now_ns, FrameOut& out);
  void tick(std::int64_t now_ns, FrameOut& out) override;

  canopen::Cia402State state() const { return state_; }
  std::uint16_t statusword() const;
  std::int8_t mode() const { return mode_; }
  std::int32_t position_counts() const { return position_counts_; }
  std::int32_t target_counts() const { return target_counts_; }
  std::vector<std::uint16_t> controlwords;  // every controlword received, in order
  double sync_period_s = 0.001;             // velocity = step / period

 protected:
  std::uint32_t od_read(canopen::SdoAddress address, std::uint32_t& value, std::uint8_t& size) override;
  std::uint32_t od_write(canopen::SdoAddress address, std::uint32_t value, std::uint8_t size) override;
  void on_reset_node() override;
  void on_pdo_or_sync(const CanFrame& frame, std::int64_t now_ns, FrameOut& out) override;

 private:
  void apply_controlword(std::uint16_t controlword);

  canopen::Cia402State state_ = canopen::Cia402State::switch_on_disabled;
  std::int8_t mode_ = 0;
  std::int32_t position_counts_ = 0;
  std::int32_t velocity_counts_per_s_ = 0;
  std::int32_t target_counts_ = 0;
  std::uint16_t last_controlword_ = 0;
  std::uint16_t pending_fault_code_ = 0;
};

class SimLoadCell final : public SimNode {
 public:
  explicit SimLoadCell(std::uint8_t node_id) : SimNode(node_id) {}

  canopen::LoadCellTpdo1 sample{{0, 0}, canopen::kLoadCellCh0Valid | canopen::kLoadCellCh1Valid, 0};
  bool advance_sequence = true;  // false: a stuck sensor repeating its sample

 protected:
  std::uint32_t od_read(canopen::SdoAddress address, std::uint32_t& value, std::uint8_t& size) override;
  std::uint32_t od_write(canopen::SdoAddress address, std::uint32_t value, std::uint8_t size) override;
  void on_pdo_or_sync(const CanFrame& frame, std::int64_t now_ns, FrameOut& out) override;
};

}  // namespace tensegrity::fw::sim
