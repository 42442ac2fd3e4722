// SPDX-License-Identifier: Apache-2.0
// The end cap DDS node's settings (firmware/comms/node/endcap_node.hpp).
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string>

#include "firmware/comms/wire/policy_wire.hpp"
#include "firmware/comms/wire/start_grid.hpp"

namespace tensegrity::fw::comms {

enum class HostLossAction : std::uint8_t { continue_gait = 0, stop = 1 };
const char* to_string(HostLossAction action);
// "continue" | "stop"; throws std::invalid_argument naming the accepted values.
HostLossAction parse_host_loss_action(const std::string& text);

struct EndcapNodeConfig {
  int endcap_id = 0;
  int domain = 42;
  // DDS Security: this end cap's enclave folder (msgs/security.hpp). Empty: unsecured.
  std::filesystem::path enclave_dir;
  PolicyExpectations expect{};  // endcap_id is overwritten with `endcap_id`
  double telemetry_rate_hz = 100.0;
  double heartbeat_rate_hz = 5.0;
  double time_sync_interval_s = 0.2;
  // No host heartbeat for this long (after one was seen) is a lost host.
  double host_timeout_s = 1.0;
  // No host heard within this long of the node's start is a lost host too, so an
  // end cap started on boot (or restarted) that never hears one does not roll on
  // unwatched. Long enough for a secured discovery of twelve end caps on a loaded
  // machine (up to 14 s seen, docs/guide/security.md).
  double host_boot_grace_s = 30.0;
  // Stop, latched as the fault host_lost (a clear-fault and a start to go on), as a
  // drive does when its master goes quiet (CiA 402's abort connection); continue
  // keeps an open-loop gait playing, only when configured so.
  HostLossAction host_loss = HostLossAction::stop;
  // Hearing hosts that hear other end caps but have not named this one for this
  // long, the node makes a new participant: a stalled security handshake in one
  // direction outlives any number of fresh hosts (docs/guide/security.md). The wait
  // doubles after each rejoin that is not answered, up to 8 times. 0: never.
  double unheard_rejoin_s = 20.0;
  double loop_ack_timeout_s = 2.0;
  // A start issued longer ago than this (host time) is refused as stale: it would
  // start in the wrong phase. Only starts are judged by a clock (command_gate.hpp).
  double command_max_age_s = 5.0;
  bool log = true;  // one line per event to stderr
  // Lockstep (loop time = SYNC count x period): the start grid (start_time.hpp).
  // 0: no grid (a free-running loop maps host time directly).
  std::int64_t start_grid_ns = 0;
  // Fault injection (HIL): while *link_cut is true the participant's transport
  // drops every datagram in and out (msgs/link_cut_transport.hpp). Null: never cut.
  const std::atomic<bool>* link_cut = nullptr;
  // Fault injection (HIL): each time *mute_requests grows, the participant of that
  // moment sends nothing more, for good, and still hears: the symptom of a security
  // handshake stalled one way (docs/guide/security.md), which a new participant clears
  // (node_rejoin.cpp). A counter, so that a signal handler can ask twice. Null: never.
  const std::atomic<std::uint32_t>* mute_requests = nullptr;
  // Watchdog: the control loop's progress counter (bumped by the loop thread every
  // pass, a lockstep wait for SYNC included). When it stands still for
  // loop_stall_timeout_s the node withholds its heartbeat, so the host sees a hung
  // loop as a silent end cap. Null: no watchdog.
  const std::atomic<std::uint64_t>* loop_progress = nullptr;
  double loop_stall_timeout_s = 0.5;
};

// Checks rates and timeouts; throws std::invalid_argument naming the field.
void validate(const EndcapNodeConfig& config);

}  // namespace tensegrity::fw::comms
