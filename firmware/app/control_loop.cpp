// SPDX-License-Identifier: Apache-2.0
#include "firmware/app/control_loop.hpp"

#include <cmath>
#include <cstdio>

#include "firmware/drivers/cob_id.hpp"

namespace tensegrity::fw::app {

using canopen::BringUpStep;
using canopen::Cia402State;
using canopen::NmtState;
using canopen::NodeRole;
using canopen::PowerRequest;
using core::FaultCause;

namespace {
constexpr double kNsToS = 1e-9;

// Counters wrap: `a` is newer than `b` when it is less than half the range ahead.
bool ahead(std::uint32_t a, std::uint32_t b) { return static_cast<std::int32_t>(a - b) > 0; }

bool is_sync(const CanFrame& f) { return !f.extended && !f.rtr && f.id == canopen::kSyncCobId && f.dlc <= 1; }

bool quick_stops(FaultCause c) {
  switch (c) {
    case FaultCause::drive_fault:
    case FaultCause::drive_lost:
    case FaultCause::emergency_stop:
    case FaultCause::node_rebooted:
    case FaultCause::loop_stalled:
    case FaultCause::node_not_operational:
    case FaultCause::drive_disabled: return true;
    default: return false;
  }
}
}  // namespace

ControlLoop::ControlLoop(CanBus& bus, Clock& clock, HostLink& host, const LoopSettings& settings)
    : bus_(bus),
      clock_(clock),
      host_(host),
      settings_(settings),
      master_(bus, settings.master),
      controller_(settings.core),
      safety_(settings.safety) {
  for (std::uint32_t m = 0; m < core::kMaxMotorsPerEndcap; ++m) commanded_m_[m] = controller_.commanded_m(m);
}

bool ControlLoop::drives_enabled() const {
  if (master_.bring_up_step() != BringUpStep::done) return false;
  for (std::size_t i = 0; i < master_.drive_count(); ++i) {
    if (master_.drive(i).state != Cia402State::operation_enabled) return false;
  }
  return true;
}

void ControlLoop::emit(AppEventKind kind, std::int64_t time_ns, FaultCause cause) {
  AppEvent e;
  e.kind = kind;
  e.time_ns = time_ns;
  e.cause = cause;
  events_.push(e);
}

// Motors hold where they are: the commanded length becomes the measured one, so a
// drive that lagged its target does not carry on towards it.
void ControlLoop::hold_at_measured() {
  std::array<double, core::kMaxMotorsPerEndcap> measured{};
  for (std::uint32_t m = 0; m < settings_.core.motor_count; ++m) {
    const canopen::DriveStatus& d = master_.drive(m);
    measured[m] = d.seen ? d.rest_length_m : controller_.commanded_m(m);
  }
  controller_.reset_commanded({measured.data(), settings_.core.motor_count});
}

void ControlLoop::latch(FaultCause cause, std::int64_t time_ns) {
  if (cause == FaultCause::none) return;
  const bool first = controller_.fault() == FaultCause::none;
  controller_.trip(cause);
  // A drive that faulted, vanished, rebooted or fell out of operation enabled, a
  // stalled loop or an operator's stop: the drives go to quick stop (decelerate,
  // then hold with power on), also when a milder fault is latched already. Sensor
  // faults (a stale position included: the drive is alive, its heartbeat watched)
  // and over-tension keep the drives enabled, holding the last measured position.
  if (quick_stops(cause)) {
    master_.request_power(PowerRequest::quick_stop);
    quick_stop_latched_ = true;  // also under a milder fault latched first
  }
  if (!first) return;
  pending_start_ = false;
  hold_at_measured();
  emit(AppEventKind::fault_latched, time_ns, cause);
}

void ControlLoop::try_start(std::int64_t start_time_ns, std::int64_t time_ns) {
  if (!drives_enabled() || !controller_.start(start_time_ns)) {
    emit(AppEventKind::start_refused, time_ns, controller_.fault());
    return;
  }
  emit(AppEventKind::started, time_ns);
}

void ControlLoop::handle_bring_up(std::int64_t time_ns) {
  if (!bring_up_started_) {
    master_.start_bring_up(time_ns);
    bring_up_started_ = true;
    bring_up_reported_ = false;
  }
  const BringUpStep step = master_.bring_up_step();
  if (step == BringUpStep::failed) {
    if (!bring_up_reported_) {
      AppEvent e;
      e.kind = AppEventKind::bring_up_failed;
      e.time_ns = time_ns;
      std::snprintf(e.text.data(), e.text.size(), "%s", master_.bring_up_failure());
      events_.push(e);
      bring_up_reported_ = true;
      bring_up_retry_at_ns_ = time_ns + settings_.bring_up_retry_ns;
    } else if (time_ns >= bring_up_retry_at_ns_) {
      bring_up_started_ = false;  // start again next cycle
    }
    return;
  }
  if (step != BringUpStep::done) {
    // Until the drives are enabled their targets are their own positions; the core
    // starts from there so enabling never jumps.
    hold_at_measured();
    return;
  }
  if (!bring_up_reported_) {
    bring_up_reported_ = true;
    emit(AppEventKind::bring_up_done, time_ns);
    if (settings_.start_on_boot && !started_on_boot_) {
      started_on_boot_ = true;
      try_start(time_ns, time_ns);
    }
  }
}

// Counters the host link raises (emergency_stops, host_loss_stops): a count ahead of
// the last one applied is a stop to apply now; an older one was applied already.
void ControlLoop::apply_host_stops(std::uint32_t estops, std::uint32_t host_loss_stops, std::int64_t time_ns) {
  if (ahead(estops, estops_seen_)) {
    estops_seen_ = estops;
    latch(FaultCause::emergency_stop, time_ns);
  }
  // A host lost while the gait plays (or is about to) is latched: nobody watches the
  // robot, so it holds until someone clears it and starts it again. An idle end cap
  // has nothing to stop, and a start can only come from a host that is back.
  if (ahead(host_loss_stops, host_loss_stops_seen_)) {
    host_loss_stops_seen_ = host_loss_stops;
    if (controller_.mode() == core::Mode::running || pending_start_) latch(FaultCause::host_lost, time_ns);
  }
}

void ControlLoop::apply_command(const HostCommand& command, std::int64_t time_ns) {
  switch (command.kind) {
    case CommandKind::start:
      if (command.start_time_ns > time_ns && drives_enabled() && controller_.has_table() &&
          controller_.fault() == FaultCause::none) {
        pending_start_ = true;
        pending_start_ns_ = command.start_time_ns;
      } else {
        try_start(command.start_time_ns, time_ns);
      }
      break;
    case CommandKind::stop:
      pending_start_ = false;
      if (controller_.mode() == core::Mode::running) emit(AppEventKind::stopped, time_ns);
      controller_.stop();
      break;
    case CommandKind::emergency_stop: latch(FaultCause::emergency_stop, time_ns); break;
    case CommandKind::clear_fault: {
      if (controller_.fault() == FaultCause::none) break;
      const FaultCause was = controller_.fault();
      controller_.clear_fault();
      quick_stop_latched_ = false;
      hold_at_measured();
      master_.request_fault_reset();
      master_.request_power(PowerRequest::operation_enabled);
      safety_.begin_fault_reset(time_ns + settings_.fault_reset_grace_ns);
      // A node that rebooted while lost is pre-operational again: bring it up anew.
      bool all_operational =
          master_.heartbeat(NodeRole::load_cell).state == NmtState::operational || !settings_.master.use_load_cell;
      for (std::size_t i = 0; i < master_.drive_count(); ++i) {
        all_operational = all_operational && master_.drive_heartbeat(i).state == NmtState::operational;
      }
      if (!all_operational) bring_up_started_ = false;
      emit(AppEventKind::fault_cleared, time_ns, was);
      break;
    }
  }
}

void ControlLoop::handle_host(std::int64_t time_ns) {
  // The counters first: the link queues a command before it counts a later estop,
  // so each command sent before an estop counted here is queued now and applied
  // first. Read after the queue ran dry, the count could take in an estop whose
  // earlier clear-fault, queued in between, would be applied after it and undo it.
  const std::uint32_t estops = host_.emergency_stops();
  const std::uint32_t host_loss_stops = host_.host_loss_stops();
  HostCommand command;
  while (host_.try_take_command(command)) {
    // An estop sent before this command lands first (HostCommand::estops_before).
    if (ahead(command.estops_before, estops_seen_)) {
      apply_host_stops(command.estops_before, host_loss_stops_seen_, time_ns);
    }
    apply_command(command, time_ns);
  }
  apply_host_stops(estops, host_loss_stops, time_ns);
  if (pending_start_ && time_ns >= pending_start_ns_) {
    pending_start_ = false;
    try_start(pending_start_ns_, time_ns);
  }
  HostTable incoming;
  while (host_.try_take_table(incoming)) {
    const core::TableError error = controller_.load(incoming.table);
    table_ack_sequence_ = incoming.sequence;
    table_ack_error_ = error;
    AppEvent e;
    e.kind = error == core::TableError::none ? AppEventKind::table_accepted : AppEventKind::table_rejected;
    e.time_ns = time_ns;
    e.table_error = error;
    events_.push(e);
  }
}

void ControlLoop::drain_bus(std::int64_t time_ns) {
  CanFrame frame;
  for (int n = 0; n < kMaxFramesPerCycle; ++n) {
    if (bus_.receive(frame, 0) != CanResult::ok) return;
    master_.on_frame(frame, time_ns);
  }
  ++status_.drain_limited_cycles;  // frames may remain: the next cycle takes them
}

void ControlLoop::cycle(std::int64_t time_ns, double dt_s) {
  master_.poll(time_ns);
  handle_bring_up(time_ns);

  canopen::MasterEvent me;
  while (master_.pop_event(me)) {
    latch(safety_.on_event(me, master_), time_ns);
    AppEvent e;
    e.kind = AppEventKind::master_event;
    e.time_ns = time_ns;
    e.master_kind = me.kind;
    e.node_id = me.node_id;
    e.emcy_code = me.emcy.error_code;
    events_.push(e);
  }
  handle_host(time_ns);

  // A clear that found a node out of operational asked for a new bring-up (next
  // cycle): until that is done the node is expected to be out of operational.
  const bool armed = bring_up_started_ && master_.bring_up_step() == BringUpStep::done;
  latch(safety_.check(master_, time_ns, armed), time_ns);
  // A stop latched before or during a bring-up outlasts it: the bring-up's own
  // request to enable the drives must not undo an operator's stop.
  if (quick_stop_latched_) master_.request_power(PowerRequest::quick_stop);

  // The newest valid reading per motor; a channel that stays invalid trips
  // sensor_timeout above, so holding the last value bridges single bad samples only.
  const canopen::LoadCellStatus& lc = master_.load_cell();
  for (std::uint32_t m = 0; m < settings_.core.motor_count && m < 2; ++m) {
    if (settings_.master.use_load_cell && lc.seen && lc.valid[m]) tension_n_[m] = lc.tension_n[m];
  }

  const FaultCause before = controller_.fault();
  const std::uint32_t n = settings_.core.motor_count;
  core::StepStatus step = controller_.step(time_ns, dt_s, {tension_n_.data(), n}, {commanded_m_.data(), n});
  if (before == FaultCause::none && step.fault != FaultCause::none) {
    // The core tripped by itself (over-tension): hold within this same cycle.
    controller_.trip(step.fault);
    hold_at_measured();
    for (std::uint32_t m = 0; m < n; ++m) commanded_m_[m] = controller_.commanded_m(m);
    pending_start_ = false;
    emit(AppEventKind::fault_latched, time_ns, step.fault);
  }
  if (step.table_swapped) emit(AppEventKind::table_swapped, time_ns);

  for (std::uint32_t m = 0; m < n; ++m) {
    if (master_.write_target(m, commanded_m_[m]) != CanResult::ok) ++status_.send_failures;
  }
  // In lockstep the HIL produces SYNC; a second producer would double the ticks.
  if (settings_.mode == LoopMode::realtime && master_.send_sync() != CanResult::ok) ++status_.send_failures;
  // A batching bus sends the cycle's frames (targets, SYNC, SDO, NMT) as one
  // datagram now: one system call and one wake-up of the other side per cycle.
  if (bus_.flush() != CanResult::ok) ++status_.send_failures;

  ++status_.cycles;
  status_.time_ns = time_ns;
  publish(time_ns, step);
}

void ControlLoop::publish(std::int64_t time_ns, const core::StepStatus& step) {
  Telemetry& t = telemetry_;
  t.time_ns = time_ns;
  t.cycle = status_.cycles;
  t.mode = controller_.mode();
  t.fault = controller_.fault();
  t.motor_count = settings_.core.motor_count;
  t.subinterval = step.subinterval;
  t.cutoff_mask = step.cutoff_mask;
  t.drives_enabled = drives_enabled();
  t.has_table = controller_.has_table();
  for (std::uint32_t m = 0; m < settings_.core.motor_count; ++m) {
    t.commanded_rest_length_m[m] = commanded_m_[m];
    t.measured_rest_length_m[m] = master_.drive(m).rest_length_m;
    t.tension_n[m] = tension_n_[m];
  }
  t.table_ack_sequence = table_ack_sequence_;
  t.table_ack_error = table_ack_error_;
  t.overruns = status_.overruns;
  host_.publish(t);
}

void ControlLoop::run_realtime_cycle() {
  if (!timer_started_) {
    timer_started_ = true;
    origin_ns_ = clock_.now_ns();
    next_deadline_ns_ = origin_ns_;
    previous_time_ns_ = -settings_.period_ns;
  }
  clock_.sleep_until_ns(next_deadline_ns_);
  const std::int64_t wake_ns = clock_.now_ns();
  const std::int64_t latency_ns = wake_ns - next_deadline_ns_;
  wakeup_window_.add(latency_ns);
  wakeup_total_.add(latency_ns);
  if (latency_ns > settings_.period_ns / 2) ++status_.late_wakeups;

  const std::int64_t time_ns = wake_ns - origin_ns_;
  const double dt_s = static_cast<double>(time_ns - previous_time_ns_) * kNsToS;
  // After a gap the drives may have stopped themselves (0x6007) while the cached
  // states still say "operation enabled": latch before this cycle sends anything,
  // or its "enable operation" would re-enable them (CiA 402 transition 16).
  if (settings_.stall_limit_ns > 0 && time_ns - previous_time_ns_ > settings_.stall_limit_ns &&
      master_.bring_up_step() == BringUpStep::done) {
    ++status_.stalls;
    latch(FaultCause::loop_stalled, time_ns);
  }
  previous_time_ns_ = time_ns;
  drain_bus(time_ns);
  cycle(time_ns, dt_s);

  const std::int64_t end_ns = clock_.now_ns();
  cycle_window_.add(end_ns - wake_ns);
  cycle_total_.add(end_ns - wake_ns);
  next_deadline_ns_ += settings_.period_ns;
  if (end_ns > next_deadline_ns_) {
    // Missed deadlines are skipped, not caught up with a burst of cycles.
    ++status_.overruns;
    const std::int64_t missed = (end_ns - next_deadline_ns_) / settings_.period_ns + 1;
    next_deadline_ns_ += missed * settings_.period_ns;
  }
  update_status();
}

// The counters every cycle; percentiles and the hand-over once per window.
void ControlLoop::update_status() {
  status_.mode = controller_.mode();
  status_.fault = controller_.fault();
  status_.bring_up = master_.bring_up_step();
  status_.syncs_received = master_.sync().received;
  status_.rx_drops = master_.rx_drops().total();
  status_.events_lost = events_.dropped();
  if (status_.cycles % settings_.stats_window_cycles != 0) return;
  status_.cycle_window = cycle_window_.summary();
  status_.wakeup_window = wakeup_window_.summary();
  cycle_window_.clear();
  wakeup_window_.clear();
  status_out_.write(status_);
}

bool ControlLoop::run_lockstep_cycle(std::int64_t wait_timeout_ns) {
  const std::int64_t give_up_ns = clock_.now_ns() + wait_timeout_ns;
  CanFrame frame;
  for (;;) {
    const std::int64_t remaining_ns = give_up_ns - clock_.now_ns();
    if (remaining_ns <= 0) return false;
    const std::int64_t tick_time_ns = static_cast<std::int64_t>(ticks_) * settings_.period_ns;
    if (bus_.receive(frame, remaining_ns) != CanResult::ok) return false;
    master_.on_frame(frame, tick_time_ns);
    if (is_sync(frame)) break;
  }
  const std::int64_t wake_ns = clock_.now_ns();
  ++ticks_;
  cycle(static_cast<std::int64_t>(ticks_) * settings_.period_ns, static_cast<double>(settings_.period_ns) * kNsToS);
  const std::int64_t duration_ns = clock_.now_ns() - wake_ns;
  cycle_window_.add(duration_ns);
  cycle_total_.add(duration_ns);
  if (duration_ns > settings_.period_ns) ++status_.overruns;
  update_status();
  return true;
}

}  // namespace tensegrity::fw::app
