// SPDX-License-Identifier: Apache-2.0
// Decides, once per cycle, whether the end cap must go to its safe state and why.
// Two sources: master events (an EMCY or a lost heartbeat is a fact the moment it
// arrives) and the state the master holds (a drive still in fault, a heartbeat
// still missing, a load cell that stopped producing fresh samples). The state
// checks are armed once bring-up is done; before that nodes are expected to be
// silent or booting. The controller latches the first cause; while a condition
// persists this monitor keeps reporting it, so clearing a fault that is still
// there trips again on the next cycle. Over-tension is the core's own check.
// Supervision (docs/design/canopen.md): a boot-up after bring-up (a node that rebooted
// comes back pre-operational and unpowered), a drive out of operation enabled
// that was not asked to leave it, and a drive position older than its timeout.
#pragma once

#include <cstdint>

#include "core/fault.hpp"
#include "firmware/drivers/canopen_master.hpp"

namespace tensegrity::fw::app {

struct SafetyConfig {
  std::uint32_t motor_count = 2;
  bool use_load_cell = true;
  std::int64_t load_cell_sample_timeout_ns = 20'000'000;
  std::int64_t drive_position_timeout_ns = 20'000'000;
};

class SafetyMonitor {
 public:
  explicit SafetyMonitor(const SafetyConfig& config) : config_(config) {}

  // Every master event of this cycle; returns the cause it implies, or none.
  core::FaultCause on_event(const canopen::MasterEvent& event, const canopen::CanopenMaster& master);
  // After the events: conditions that persist. `armed`: bring-up is done.
  core::FaultCause check(const canopen::CanopenMaster& master, std::int64_t now_ns, bool armed);
  // A clear-fault's reset handshake walks the drives through states other than
  // operation enabled: until `until_ns` their power state is not judged, while
  // every other check (heartbeats, positions, load cell) goes on.
  void begin_fault_reset(std::int64_t until_ns) { reset_until_ns_ = until_ns; }

  // Last time each load-cell channel delivered a fresh, valid sample.
  std::int64_t channel_fresh_ns(std::uint32_t channel) const { return fresh_ns_[channel]; }

 private:
  bool is_drive(std::uint8_t node_id, const canopen::CanopenMaster& master) const;

  SafetyConfig config_;
  std::uint8_t last_sequence_ = 0;
  bool sequence_seen_ = false;
  bool was_armed_ = false;
  std::int64_t fresh_ns_[2] = {0, 0};
  std::int64_t armed_ns_ = 0;  // positions are judged from here at the earliest
  std::int64_t reset_until_ns_ = 0;
};

}  // namespace tensegrity::fw::app
