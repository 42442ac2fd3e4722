// SPDX-License-Identifier: Apache-2.0
// One end cap's control loop: read sensors (drain CAN frames into the master),
// check safety, step the control core, write the drive targets. Pure with respect
// to the OS: the bus, the clock and the host link are interfaces, so tests run it
// with a ManualClock and an in-memory bus. After construction nothing here
// allocates, throws or blocks except where the bus is waited on (lockstep).
//
// Time: the core and the master see "loop time". Realtime: monotonic clock since
// the loop's first cycle; the loop sends SYNC after writing targets. Lockstep:
// SYNC count x period, one cycle per SYNC received; the loop never sends SYNC.
// Either way the core gets the same step() call and cannot tell the difference.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "firmware/app/config.hpp"
#include "firmware/app/host_link.hpp"
#include "firmware/app/loop_stats.hpp"
#include "firmware/app/mailbox.hpp"
#include "firmware/app/safety.hpp"
#include "core/endcap_controller.hpp"
#include "firmware/drivers/canopen_master.hpp"
#include "firmware/hal/can_bus.hpp"
#include "firmware/hal/clock.hpp"

namespace tensegrity::fw::app {

struct LoopSettings {
  core::EndcapConfig core;
  canopen::CanopenMasterConfig master;
  SafetyConfig safety;
  LoopMode mode = LoopMode::realtime;
  std::int64_t period_ns = 1'000'000;
  bool start_on_boot = false;
  std::int64_t bring_up_retry_ns = 2'000'000'000;
  // After a clear, a drive gets this long to leave its fault state before the
  // state check trips again (the fault-reset handshake takes a few cycles).
  std::int64_t fault_reset_grace_ns = 200'000'000;
  // Real time: a gap between cycles longer than this is a stall (0: not checked).
  std::int64_t stall_limit_ns = 0;
  std::uint64_t stats_window_cycles = 10'000;
};

LoopSettings make_loop_settings(const EndcapAppConfig& config);

enum class AppEventKind : std::uint8_t {
  bring_up_done,
  bring_up_failed,  // a retry follows after bring_up_retry_ns
  fault_latched,
  fault_cleared,
  table_accepted,
  table_rejected,
  table_swapped,
  started,
  start_refused,  // no table, faulted, or drives not enabled
  stopped,
  master_event,
};

const char* to_string(AppEventKind kind);

struct AppEvent {
  AppEventKind kind = AppEventKind::master_event;
  std::int64_t time_ns = 0;
  core::FaultCause cause = core::FaultCause::none;
  core::TableError table_error = core::TableError::none;
  canopen::MasterEventKind master_kind = canopen::MasterEventKind::boot_up;
  std::uint8_t node_id = 0;
  std::uint16_t emcy_code = 0;
  std::array<char, 128> text{};  // bring_up_failed: the master's one-line reason
};

// A snapshot for the periodic log line; the window is the last stats_window_cycles.
struct LoopStatus {
  std::int64_t time_ns = 0;
  std::uint64_t cycles = 0;
  std::uint64_t stalls = 0;        // realtime gaps longer than stall_limit_ns (each latches loop_stalled)
  std::uint64_t overruns = 0;      // a cycle ended after the next deadline (realtime) or took > period
  std::uint64_t late_wakeups = 0;  // woke more than half a period after the deadline
  std::uint64_t syncs_received = 0;
  std::uint64_t send_failures = 0;
  std::uint64_t rx_drops = 0;
  TimingSummary cycle_window;   // wake-up to targets sent
  TimingSummary wakeup_window;  // deadline to wake-up (realtime only)
  core::Mode mode = core::Mode::idle;
  core::FaultCause fault = core::FaultCause::none;
  canopen::BringUpStep bring_up = canopen::BringUpStep::idle;
  std::uint64_t events_lost = 0;
  // Cycles whose bus drain stopped at kMaxFramesPerCycle with frames still queued.
  std::uint64_t drain_limited_cycles = 0;
};

class ControlLoop {
 public:
  ControlLoop(CanBus& bus, Clock& clock, HostLink& host, const LoopSettings& settings);

  // Before running: a table restored from storage or given with --policy.
  core::TableError load_table(const core::EndcapTable& table) { return controller_.load(table); }

  // Realtime: sleeps until the next absolute deadline, drains the bus, one cycle.
  void run_realtime_cycle();
  // Lockstep: feeds frames to the master until a SYNC arrives (then runs exactly
  // one cycle and returns true; later frames stay queued for the next cycle) or
  // until `wait_timeout_ns` passes (false, no cycle).
  bool run_lockstep_cycle(std::int64_t wait_timeout_ns);

  // Building blocks, public for tests: the control cycle at loop time `time_ns`,
  // and draining the frames already queued on the bus into the master, at most
  // kMaxFramesPerCycle of them: a flooded bus must not starve the cycle. What is
  // left waits for the next cycle (counted in LoopStatus::drain_limited_cycles).
  static constexpr int kMaxFramesPerCycle = 256;
  void cycle(std::int64_t time_ns, double dt_s);
  void drain_bus(std::int64_t time_ns);

  const core::EndcapController& controller() const { return controller_; }
  const canopen::CanopenMaster& master() const { return master_; }
  const LoopStatus& status() const { return status_; }
  const Histogram& cycle_histogram() const { return cycle_total_; }
  const Histogram& wakeup_histogram() const { return wakeup_total_; }
  std::span<const double> commanded_m() const { return {commanded_m_.data(), settings_.core.motor_count}; }
  bool drives_enabled() const;
  // Realtime: the clock reading at loop time 0 (0 before the first cycle, and in lockstep).
  std::int64_t clock_origin_ns() const { return origin_ns_; }

  // For the other thread (housekeeping): events to log, status. Tables are
  // persisted before they reach the loop (the DDS node, with their identity).
  bool pop_event(AppEvent& event) { return events_.pop(event); }
  bool read_status(LoopStatus& status) { return status_out_.read(status); }

 private:
  void emit(AppEventKind kind, std::int64_t time_ns, core::FaultCause cause = core::FaultCause::none);
  void latch(core::FaultCause cause, std::int64_t time_ns);
  void hold_at_measured();
  void handle_bring_up(std::int64_t time_ns);
  void handle_host(std::int64_t time_ns);
  void apply_command(const HostCommand& command, std::int64_t time_ns);
  void apply_host_stops(std::uint32_t estops, std::uint32_t host_loss_stops, std::int64_t time_ns);
  void try_start(std::int64_t start_time_ns, std::int64_t time_ns);
  void publish(std::int64_t time_ns, const core::StepStatus& step);
  void update_status();

  CanBus& bus_;
  Clock& clock_;
  HostLink& host_;
  LoopSettings settings_;
  canopen::CanopenMaster master_;
  core::EndcapController controller_;
  SafetyMonitor safety_;

  std::array<double, core::kMaxMotorsPerEndcap> tension_n_{};
  std::array<double, core::kMaxMotorsPerEndcap> commanded_m_{};
  bool bring_up_started_ = false;
  bool bring_up_reported_ = false;
  std::int64_t bring_up_retry_at_ns_ = 0;
  bool pending_start_ = false;
  std::int64_t pending_start_ns_ = 0;
  bool started_on_boot_ = false;
  std::uint32_t table_ack_sequence_ = 0;
  core::TableError table_ack_error_ = core::TableError::none;
  std::uint32_t estops_seen_ = 0;
  std::uint32_t host_loss_stops_seen_ = 0;
  bool quick_stop_latched_ = false;  // a quick-stopping cause latched, first or not, until cleared

  // Realtime pacing.
  bool timer_started_ = false;
  std::int64_t origin_ns_ = 0;
  std::int64_t next_deadline_ns_ = 0;
  std::int64_t previous_time_ns_ = 0;
  // Lockstep.
  std::uint64_t ticks_ = 0;

  LoopStatus status_;
  Histogram cycle_window_;
  Histogram wakeup_window_;
  Histogram cycle_total_;
  Histogram wakeup_total_;
  Telemetry telemetry_;

  SpscRing<AppEvent, 256> events_;
  LatestValue<LoopStatus> status_out_;
};

}  // namespace tensegrity::fw::app
