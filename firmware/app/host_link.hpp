// SPDX-License-Identifier: Apache-2.0
// The seam between the control loop and the host (DDS over Wi-Fi, next issue:
// firmware/comms implements it). The loop polls it once per cycle from its own
// thread, so every call must return at once, must not allocate and must not take
// a lock the other side may hold: implementations hand data over through
// mailbox.hpp (SpscRing for tables and commands, LatestValue for telemetry).
#pragma once

#include <array>
#include <cstdint>

#include "core/endcap_controller.hpp"
#include "core/fault.hpp"
#include "core/limits.hpp"
#include "core/table.hpp"

namespace tensegrity::fw::app {

struct HostTable {
  std::uint32_t sequence = 0;  // echoed in Telemetry::table_ack_sequence
  core::EndcapTable table;
};

enum class CommandKind : std::uint8_t { start, stop, emergency_stop, clear_fault };

struct HostCommand {
  CommandKind kind = CommandKind::stop;
  // start: loop time (ns, the loop's own clock: monotonic in realtime, SYNC ticks x
  // period in lockstep) at which table time 0 falls. In the past: start at once,
  // with the table already that far along (keeps end caps in step). The comms
  // layer maps host time to loop time.
  std::int64_t start_time_ns = 0;
  // HostLink::emergency_stops() when the command was queued: an estop the host
  // sent before this command is applied before it, even when both reach the loop
  // in one cycle (an estop then a clear-fault must end cleared, not stopped).
  std::uint32_t estops_before = 0;
};

struct Telemetry {
  std::int64_t time_ns = 0;
  std::uint64_t cycle = 0;
  core::Mode mode = core::Mode::idle;
  core::FaultCause fault = core::FaultCause::none;
  std::uint32_t motor_count = 0;
  std::uint32_t subinterval = 0;
  std::uint8_t cutoff_mask = 0;
  bool drives_enabled = false;  // bring-up done and every drive in operation enabled
  bool has_table = false;       // a policy table is loaded (a start can play)
  std::array<double, core::kMaxMotorsPerEndcap> commanded_rest_length_m{};
  std::array<double, core::kMaxMotorsPerEndcap> measured_rest_length_m{};
  std::array<double, core::kMaxMotorsPerEndcap> tension_n{};
  std::uint32_t table_ack_sequence = 0;  // the last HostTable taken
  core::TableError table_ack_error = core::TableError::none;
  std::uint64_t overruns = 0;
};

// What the link saw happen, counted (the log says it in words): the host's heartbeat
// lost and back, the link cut by fault injection, the control loop seen stalled by
// the node's watchdog, new participants made because no host heard this end cap.
// Read by the housekeeping thread for --stats-json.
struct LinkEvents {
  std::uint64_t host_losses = 0;
  std::uint64_t host_returns = 0;
  std::uint64_t link_cuts = 0;
  std::uint64_t loop_stalls = 0;
  std::uint64_t rejoins = 0;
  LinkEvents& operator+=(const LinkEvents& o) {
    host_losses += o.host_losses;
    host_returns += o.host_returns;
    link_cuts += o.link_cuts;
    loop_stalls += o.loop_stalls;
    rejoins += o.rejoins;
    return *this;
  }
  bool operator==(const LinkEvents&) const = default;
};

class HostLink {
 public:
  virtual ~HostLink() = default;
  // Each returns true and fills `out` when the host sent something since the last call.
  virtual bool try_take_table(HostTable& out) noexcept = 0;
  virtual bool try_take_command(HostCommand& out) noexcept = 0;
  // Called every cycle; an implementation keeps the newest and sends at its own rate.
  virtual void publish(const Telemetry& telemetry) noexcept = 0;
  // Read every cycle: how many emergency stops the host has sent, and how many
  // host-loss stops the link has ordered. Counters, not mailbox entries: one can
  // never be refused for a full queue or lost, and the loop latches the safe state
  // in the cycle after it changes.
  virtual std::uint32_t emergency_stops() const noexcept { return 0; }
  virtual std::uint32_t host_loss_stops() const noexcept { return 0; }
  virtual LinkEvents link_events() const noexcept { return {}; }
};

// No host yet: tables come from --policy and the store, start from --start-on-boot.
class NullHostLink final : public HostLink {
 public:
  bool try_take_table(HostTable&) noexcept override { return false; }
  bool try_take_command(HostCommand&) noexcept override { return false; }
  void publish(const Telemetry&) noexcept override {}
};

}  // namespace tensegrity::fw::app
