// SPDX-License-Identifier: Apache-2.0
// The end cap's CANopen master (CiA 301 subset) for the end cap's CiA 402 drives
// (one per motor: a SUPERball end cap winds two cables) in cyclic synchronous
// position mode and one load-cell node. Per control cycle the application:
//   1. drains the bus: while (bus.receive(f, 0) == ok) master.on_frame(f, now);
//   2. master.poll(now)              heartbeat and SDO timeouts, bring-up steps
//   3. reads drive(), load_cell(), pop_event()
//   4. master.write_target(i, length) RPDO1 of drive i: controlword + target position
//   5. master.send_sync()            the drive latches the target, nodes answer with TPDOs
// (In HIL lockstep the emulator may produce SYNC instead; on_frame records it.)
// Nothing after construction allocates or throws; every frame is checked and a
// rejected one is counted in rx_drops() and otherwise ignored.
#pragma once

#include <array>
#include <cstdint>

#include "core/loop_period.hpp"
#include "firmware/drivers/canopen_bring_up.hpp"
#include "firmware/drivers/cia402.hpp"
#include "firmware/drivers/cia402_power.hpp"
#include "firmware/drivers/emcy.hpp"
#include "firmware/drivers/event_queue.hpp"
#include "firmware/drivers/heartbeat_monitor.hpp"
#include "firmware/drivers/nmt.hpp"
#include "firmware/drivers/rx_drop.hpp"
#include "firmware/drivers/sdo_client.hpp"
#include "firmware/drivers/spool_geometry.hpp"
#include "firmware/hal/can_bus.hpp"

namespace tensegrity::fw::canopen {

enum class NodeRole : std::uint8_t { drive, load_cell };

// Matches the control core's kMaxMotorsPerEndcap: one drive per motor.
inline constexpr std::size_t kMaxDriveNodes = 4;

struct CanopenMasterConfig {
  std::uint8_t drive_node_id = 1;  // drive 0
  // Drives beyond drive 0, one per further motor: drive i (1 <= i < drive_count) is
  // extra_drive_node_ids[i - 1]. drive_count is 1..kMaxDriveNodes; all ids distinct.
  std::uint8_t drive_count = 1;
  std::array<std::uint8_t, kMaxDriveNodes - 1> extra_drive_node_ids{};
  std::uint8_t load_cell_node_id = 2;
  bool use_load_cell = true;
  // Per node: a few producer periods (nodes here beat every 20 ms or so).
  std::int64_t drive_heartbeat_timeout_ns = 100'000'000;
  std::int64_t load_cell_heartbeat_timeout_ns = 100'000'000;
  // What bring-up writes to every node's 0x1017 (producer heartbeat time, ms), so the
  // timeouts above do not rest on each device's factory default; 0: left as it is.
  std::uint16_t node_heartbeat_period_ms = 20;
  std::int64_t sdo_timeout_ns = 50'000'000;
  std::int64_t bring_up_step_timeout_ns = 2'000'000'000;
  std::uint8_t sync_counter_max = 0;  // 0: SYNC without counter; else 2..240
  // The SYNC period, which bring-up writes to every drive: 0x1006 (whole
  // microseconds) and 0x60C2 (interpolation_period() must say it).
  std::int64_t sync_period_ns = core::kDefaultLoopPeriodNs;
  // Supervision the other way (docs/design/canopen.md "Supervision"): the end cap's own
  // node id and heartbeat (its 0x1017; 0: none), which every drive is told to
  // watch in bring-up (0x1016 sub 1, consumer time; 0: not configured) with the
  // abort-connection option (0x6007) it takes by itself when the end cap falls silent.
  std::uint8_t master_node_id = 127;
  std::int64_t producer_heartbeat_period_ns = 10'000'000;
  std::uint16_t drive_consumer_heartbeat_ms = 50;
  AbortConnectionOption drive_abort_connection = AbortConnectionOption::quick_stop;
  SpoolGeometry spool;  // the same spool on every drive

  std::uint8_t drive_node(std::size_t index) const {
    return index == 0 ? drive_node_id : extra_drive_node_ids[index - 1];
  }
};

struct DriveStatus {
  bool seen = false;  // a TPDO1 has arrived
  std::uint16_t statusword = 0;
  Cia402State state = Cia402State::not_ready_to_switch_on;
  std::int32_t position_counts = 0;
  std::int32_t velocity_counts_per_s = 0;
  std::int8_t mode_display = 0;
  double rest_length_m = 0.0;             // from position through the spool
  double rest_length_rate_m_per_s = 0.0;  // from velocity
  std::int64_t position_updated_ns = 0;
  std::int64_t velocity_updated_ns = 0;
  std::uint16_t controlword_sent = 0;
  std::int32_t target_sent_counts = 0;
  bool has_emcy = false;
  EmcyMessage last_emcy;
};

struct LoadCellStatus {
  bool seen = false;
  std::array<double, 2> tension_n{};
  std::array<bool, 2> valid{};  // channel valid and not over range, no ADC fault
  std::uint8_t status = 0;
  std::uint8_t sequence = 0;
  std::uint32_t stale_samples = 0;  // sequence did not advance
  std::int64_t updated_ns = 0;
  bool has_emcy = false;
  EmcyMessage last_emcy;
};

struct SyncStatus {
  std::uint64_t sent = 0;
  std::uint64_t received = 0;  // from another producer (the HIL in lockstep)
  std::uint8_t last_counter = 0;
  std::int64_t last_received_ns = 0;
};

enum class MasterEventKind : std::uint8_t {
  boot_up,
  heartbeat_lost,
  heartbeat_restored,
  emcy,
  drive_fault,          // drive entered fault reaction / fault
  drive_fault_cleared,  // drive left fault
  sdo_finished,         // done, aborted or timed out: see sdo_transfer()
  bring_up_done,
  bring_up_failed,  // see bring_up_failure()
};

const char* to_string(MasterEventKind kind);

struct MasterEvent {
  MasterEventKind kind = MasterEventKind::boot_up;
  std::uint8_t node_id = 0;
  std::int64_t time_ns = 0;
  EmcyMessage emcy;  // kind == emcy
};

class CanopenMaster {
 public:
  static constexpr std::size_t kEventCapacity = 32;

  CanopenMaster(CanBus& bus, const CanopenMasterConfig& config);

  void on_frame(const CanFrame& frame, std::int64_t now_ns);
  void poll(std::int64_t now_ns);

  // Sends RPDO1 of drive `drive_index` (drive 0 without an index). The target is
  // the commanded rest length unless the drive is not in operation enabled: then
  // it is the drive's own position, so enabling never jumps (seed the motor loop
  // from drive(i).rest_length_m before enabling). A non-finite length is refused
  // and the drive holds position. An index >= drive_count() sends nothing.
  CanResult write_target(double rest_length_m) { return write_target(0, rest_length_m); }
  CanResult write_target(std::size_t drive_index, double rest_length_m);
  CanResult send_sync();
  CanResult send_nmt(NmtCommand command, std::uint8_t node_id);  // node 0: all

  // Power requests apply to every drive of the end cap: they act together.
  void request_power(PowerRequest request) {
    for (std::size_t i = 0; i < drive_count_; ++i) drives_[i].power.request(request);
  }
  void request_fault_reset() {
    for (std::size_t i = 0; i < drive_count_; ++i) drives_[i].power.request_fault_reset();
  }
  PowerRequest power_request() const { return drives_[0].power.requested(); }

  // Reset communication, then set CSP on each drive, verify it, start the nodes,
  // enable the drives.
  void start_bring_up(std::int64_t now_ns) { bring_up_.start(now_ns); }
  BringUpStep bring_up_step() const { return bring_up_.step(); }
  const char* bring_up_failure() const { return bring_up_.failure(); }

  // One expedited transfer per node at a time; false when busy or unknown node.
  // NodeRole::drive is drive 0.
  bool sdo_upload(NodeRole node, SdoAddress address, std::int64_t now_ns);
  bool sdo_download(NodeRole node, SdoAddress address, std::uint32_t value, std::uint8_t size_bytes,
                    std::int64_t now_ns);
  const SdoTransfer& sdo_transfer(NodeRole node) const { return sdo_client(node).transfer(); }
  void sdo_acknowledge(NodeRole node) { sdo_client(node).acknowledge(); }

  std::size_t drive_count() const { return drive_count_; }
  const DriveStatus& drive(std::size_t index = 0) const { return drives_[index].status; }
  const LoadCellStatus& load_cell() const { return load_cell_; }
  const HeartbeatStatus& heartbeat(NodeRole node) const {
    return node == NodeRole::drive ? drives_[0].hb.status() : load_cell_hb_.status();
  }
  const HeartbeatStatus& drive_heartbeat(std::size_t index) const { return drives_[index].hb.status(); }
  const SyncStatus& sync() const { return sync_; }
  // The end cap's own heartbeats sent (producer, from start_bring_up on).
  std::uint64_t heartbeats_sent() const { return heartbeats_sent_; }
  bool pop_event(MasterEvent& event) { return events_.pop(event); }
  std::uint64_t events_lost() const { return events_.overflows(); }
  const RxDropCounters& rx_drops() const { return drops_; }
  std::uint64_t frames_accepted() const { return frames_accepted_; }
  std::uint64_t targets_refused() const { return targets_refused_; }
  const CanopenMasterConfig& config() const { return config_; }

 private:
  friend class CanopenBringUp;  // the start-up sequence drives the nodes through the master
  // Everything the master keeps per drive node.
  struct DriveNode {
    DriveNode(std::uint8_t id, const CanopenMasterConfig& c)
        : hb(c.drive_heartbeat_timeout_ns), sdo(id, c.sdo_timeout_ns) {}
    HeartbeatMonitor hb;
    SdoClient sdo;
    Cia402PowerControl power;
    DriveStatus status;
  };
  // A node on the bus as the master knows it: a drive (with its index) or the load cell.
  struct NodeRef {
    NodeRole role = NodeRole::drive;
    std::size_t drive_index = 0;
  };

  static std::array<DriveNode, kMaxDriveNodes> make_drives(const CanopenMasterConfig& config);
  SdoClient& sdo_client(NodeRef node) {
    return node.role == NodeRole::drive ? drives_[node.drive_index].sdo : load_cell_sdo_;
  }
  const SdoClient& sdo_client(NodeRole node) const { return node == NodeRole::drive ? drives_[0].sdo : load_cell_sdo_; }
  SdoClient& sdo_client(NodeRole node) { return sdo_client(NodeRef{node, 0}); }
  bool node_ref(std::uint8_t node_id, NodeRef& node) const;
  std::uint8_t node_id(NodeRef node) const {
    return node.role == NodeRole::drive ? config_.drive_node(node.drive_index) : config_.load_cell_node_id;
  }
  void emit(MasterEventKind kind, std::uint8_t node_id, std::int64_t now_ns);
  void drop(RxDrop reason) { drops_.count(reason); }
  void accept() { ++frames_accepted_; }
  bool sdo_start(NodeRef node, bool upload, SdoAddress address, std::uint32_t value, std::uint8_t size_bytes,
                 std::int64_t now_ns);

  void on_heartbeat(const CanFrame& frame, NodeRef node, std::int64_t now_ns);
  void on_emcy(const CanFrame& frame, NodeRef node, std::int64_t now_ns);
  void on_drive_tpdo1(const CanFrame& frame, std::size_t drive_index, std::int64_t now_ns);
  void on_drive_tpdo2(const CanFrame& frame, std::size_t drive_index, std::int64_t now_ns);
  void on_load_cell_tpdo1(const CanFrame& frame, std::int64_t now_ns);
  void on_sdo(const CanFrame& frame, NodeRef node, std::int64_t now_ns);
  void on_sync(const CanFrame& frame, std::int64_t now_ns);

  void produce_heartbeat(std::int64_t now_ns);

  CanBus& bus_;
  CanopenMasterConfig config_;
  std::size_t drive_count_;
  std::array<DriveNode, kMaxDriveNodes> drives_;
  HeartbeatMonitor load_cell_hb_;
  SdoClient load_cell_sdo_;
  LoadCellStatus load_cell_;
  SyncStatus sync_;
  std::uint8_t next_sync_counter_ = 1;
  bool producing_heartbeat_ = false;
  std::int64_t next_heartbeat_ns_ = 0;
  std::uint64_t heartbeats_sent_ = 0;
  CanopenBringUp bring_up_{*this};
  EventQueue<MasterEvent, kEventCapacity> events_;
  RxDropCounters drops_;
  std::uint64_t frames_accepted_ = 0;
  std::uint64_t targets_refused_ = 0;
};

}  // namespace tensegrity::fw::canopen
