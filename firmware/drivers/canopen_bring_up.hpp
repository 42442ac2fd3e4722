// SPDX-License-Identifier: Apache-2.0
// CanopenMaster's start-up sequence (docs/design/canopen.md "Bring-up"): reset
// communication, wait for every node, set each node's heartbeat period, put each
// drive in cyclic synchronous position mode and check it, give each drive the SYNC
// period (communication cycle and interpolation period), tell each drive to watch
// the end cap's heartbeat, start the nodes, enable the drives. One step per poll()
// so the control loop keeps its period while the nodes come up; each step has a
// timeout, and a failure names the step and the node. It drives the nodes through
// the master it belongs to (the master's SDO clients, NMT and power requests).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace tensegrity::fw::canopen {

class CanopenMaster;

enum class BringUpStep : std::uint8_t {
  idle,
  wait_boot,                // after NMT reset communication: wait for each node's boot-up/heartbeat
  set_heartbeat_producer,   // SDO 0x1017 = node_heartbeat_period_ms on each drive, then the load cell
  set_mode,                 // SDO 0x6060 = 8 (cyclic synchronous position)
  check_mode,               // SDO 0x6061 must read 8
  set_cycle_period,         // SDO 0x1006 = the SYNC period, us
  set_interpolation_value,  // SDO 0x60C2 sub 1 = the SYNC period's value ...
  set_interpolation_index,  // ... and sub 2 its power of ten (value x 10^index s)
  set_heartbeat_consumer,   // SDO 0x1016 sub 1 = end cap's node id, consumer time (skipped when 0)
  set_abort_connection,     // SDO 0x6007 = the abort-connection option (with the consumer only)
  start_nodes,              // NMT start; wait for heartbeats saying operational
  enable,                   // CiA 402 power-up to operation enabled (needs write_target each cycle)
  done,
  failed,
};

const char* to_string(BringUpStep step);

class CanopenBringUp {
 public:
  explicit CanopenBringUp(CanopenMaster& master) : m_(master) {}
  CanopenBringUp(const CanopenBringUp&) = delete;
  CanopenBringUp& operator=(const CanopenBringUp&) = delete;

  // Reset communication, then the steps above, from poll().
  void start(std::int64_t now_ns);
  void poll(std::int64_t now_ns);
  BringUpStep step() const { return step_; }
  const char* failure() const { return failure_.data(); }

 private:
  bool step_enable(std::int64_t now_ns);
  void fail_step_after_timeout(std::int64_t now_ns);
  bool step_drive_sdo(std::int64_t now_ns, BringUpStep& next);
  bool step_producer_sdo(std::int64_t now_ns);
  void enter_step(BringUpStep step, std::int64_t now_ns);
  void fail(const char* what, std::int64_t now_ns, std::uint32_t abort_code = 0);

  CanopenMaster& m_;
  BringUpStep step_ = BringUpStep::idle;
  std::int64_t step_started_ns_ = 0;
  bool request_sent_ = false;
  // The per-node steps go through the drives in turn (set_heartbeat_producer then
  // takes the load cell as index drive_count).
  std::size_t drive_index_ = 0;
  std::array<char, 128> failure_{};
};

}  // namespace tensegrity::fw::canopen
