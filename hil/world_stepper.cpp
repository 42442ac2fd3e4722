// SPDX-License-Identifier: Apache-2.0
#include "hil/world_stepper.hpp"

#include <cmath>
#include <sstream>
#include <thread>

#include "firmware/drivers/pdo_codec.hpp"
#include "hil/hil_error.hpp"
#include "hil/pacer.hpp"

namespace tensegrity::hil {

namespace {
constexpr std::int64_t kAdmitCheckPeriodNs = 1'000'000;  // /proc/net/udp is read at most this often

double ns_to_s(std::int64_t ns) { return static_cast<double>(ns) * 1e-9; }
}  // namespace

const char* to_string(StepperMode mode) { return mode == StepperMode::lockstep ? "lockstep" : "realtime"; }

double StepperStats::sim_time_s() const { return static_cast<double>(steps) * dt_s; }

WorldStepper::WorldStepper(const sim::Robot& robot, const sim::ModelState& start, UdpHub& hub,
                           EndcapProcesses& processes, const StepperConfig& config)
    : robot_(robot),
      model_(std::make_unique<sim::Model>(robot, robot.time_step_s)),
      hub_(hub),
      processes_(processes),
      config_(config),
      period_ns_(static_cast<std::int64_t>(std::llround(robot.time_step_s * 1e9))) {
  model_->restore(start);
  stats_.dt_s = robot.time_step_s;
  const bool lockstep = config.mode == StepperMode::lockstep;
  endcaps_.reserve(robot.endcap_count());
  for (int e = 0; e < robot.endcap_count(); ++e) {
    endcaps_.push_back({EndcapDevices(e, robot.cables_of(e), config.spool, robot.motor.max_rest_length_m, lockstep)});
  }
  preferred_.assign(model_->rest_length_m().begin(), model_->rest_length_m().end());
  start_centre_ = model_->centre_m();
  out_.reserve(64);
  rx_.reserve(256);
}

double WorldStepper::distance_m() const {
  const Eigen::Vector3d d = model_->centre_m() - start_centre_;
  return std::hypot(d.x(), d.y());
}

void WorldStepper::note(const std::string& line) {
  std::ostringstream s;
  s << "t=" << stats_.sim_time_s() << " s: " << line;
  log_.push_back(s.str());
}

void WorldStepper::admit_listening() {
  static thread_local std::int64_t last_check_ns = 0;
  bool waiting = false;
  for (const Endcap& ec : endcaps_) waiting = waiting || ec.state == EndcapState::waiting_process;
  if (!waiting) return;
  const std::int64_t now = monotonic_ns();
  if (now - last_check_ns < kAdmitCheckPeriodNs) return;
  last_check_ns = now;
  for (int e = 0; e < endcap_count(); ++e) {
    Endcap& ec = endcaps_[e];
    if (ec.state != EndcapState::waiting_process || !processes_.listening(e)) continue;
    ec.state = EndcapState::live;
    ec.first_answer_pending = true;
  }
}

bool WorldStepper::all_at_gate() const {
  for (const Endcap& ec : endcaps_) {
    if (ec.state != EndcapState::live || !ec.devices.at_gate()) return false;
  }
  return true;
}

void WorldStepper::serve(const std::vector<UdpHub::Rx>& rx) {
  const std::int64_t now = now_device_ns();
  for (const UdpHub::Rx& r : rx) {
    endcaps_[r.endcap].devices.on_frame(r.frame, now, out_);
    for (const CanFrame& f : out_) hub_.queue(r.endcap, f);
    out_.clear();
  }
}

void WorldStepper::route(const std::vector<UdpHub::Rx>& rx) {
  serve(rx);
  hub_.flush();
}

void WorldStepper::lockstep_tick(bool physics) {
  if (stop_requested()) throw HilError("interrupted");
  const std::int64_t now = now_device_ns();
  const fw::CanFrame sync = fw::canopen::encode_sync(0);
  for (int e = 0; e < endcap_count(); ++e) {
    Endcap& ec = endcaps_[e];
    ec.expected = false;
    if (ec.state != EndcapState::live) continue;
    if (ec.devices.at_gate()) {
      // Paused at the start gate: no SYNC, so its time (and bring-up timeout) stands
      // still. After the start it is let through at a period boundary: in phase.
      if (!started_) continue;
      const std::int64_t p = config_.phase_period_steps;
      if (p > 0 && stats_.steps % p != 0) continue;
      ec.devices.release_gate();
      ++stats_.rejoins;
      note("end cap " + std::to_string(e) + " enabled again (table time 0 at step " + std::to_string(stats_.steps) + ")");
    }
    ec.devices.tick(now, out_);
    ec.devices.emit_sensors(out_);
    out_.push_back(sync);
    for (const CanFrame& f : out_) hub_.queue(e, f);
    out_.clear();
    ec.devices.clear_rpdo_marks();
    ec.expected = ec.awaited;
  }
  const std::int64_t t_send = monotonic_ns();
  hub_.flush();
  const std::int64_t t_wait = monotonic_ns();
  barrier(ticks_);
  const std::int64_t t_physics = monotonic_ns();
  if (physics) {
    physics_step();
    stats_.send_wall_s += ns_to_s(t_wait - t_send);
    stats_.barrier_wall_s += ns_to_s(t_physics - t_wait);
    stats_.physics_wall_s += ns_to_s(monotonic_ns() - t_physics);
  }
  ++ticks_;
}

void WorldStepper::barrier(std::int64_t tick) {
  const std::int64_t start = monotonic_ns();
  bool first = false, expected = false;
  for (const Endcap& ec : endcaps_) {
    first = first || (ec.expected && ec.first_answer_pending);
    expected = expected || ec.expected;
  }
  const std::int64_t timeout = first ? config_.first_answer_timeout_ns : config_.barrier_timeout_ns;
  const std::int64_t deadline = start + timeout;
  hub_.reset_latest_arrival();
  if (expected && !first) pace_until(start + nap_.nap_ns(), 0);
  for (;;) {
    bool done = true;
    for (const Endcap& ec : endcaps_) {
      if (ec.expected && !ec.devices.all_rpdos()) {
        done = false;
        break;
      }
    }
    if (done) break;
    rx_.clear();
    if (hub_.receive(rx_, deadline) == 0 && monotonic_ns() >= deadline) {
      std::ostringstream why;
      why << "lockstep barrier: no drive targets within " << ns_to_s(timeout) << " s of the SYNC of tick " << tick
          << (started_ ? " (physics step " + std::to_string(stats_.steps) + ")" : " (boot)") << ":";
      for (int e = 0; e < endcap_count(); ++e) {
        const Endcap& ec = endcaps_[e];
        if (!ec.expected || ec.devices.all_rpdos()) continue;
        why << " end cap " << e << " sent no RPDO1 for drive node(s) " << ec.devices.missing_rpdo_nodes() << " ("
            << processes_.describe(e) << ");";
      }
      throw HilError(why.str());
    }
    route(rx_);
  }
  for (Endcap& ec : endcaps_) {
    if (ec.expected) ec.first_answer_pending = false;
  }
  if (expected) nap_.observe((hub_.latest_arrival_ns() > 0 ? hub_.latest_arrival_ns() : monotonic_ns()) - start);
  stats_.max_barrier_wait_s = std::max(stats_.max_barrier_wait_s, ns_to_s(monotonic_ns() - start));
}

void WorldStepper::physics_step() {
  const auto rest = model_->rest_length_m();
  for (Endcap& ec : endcaps_) ec.devices.preferred(rest, preferred_);
  try {
    model_->step(preferred_);
  } catch (const sim::ModelDiverged& e) {
    throw HilError(std::string("the model diverged at step ") + std::to_string(stats_.steps) + ": " + e.what());
  }
  ++stats_.steps;
  const std::int64_t now = (ticks_ + 1) * period_ns_;
  for (double t : model_->tension_n()) stats_.max_tension_n = std::max(stats_.max_tension_n, t);
  for (Endcap& ec : endcaps_) {
    ec.devices.update_from_model(model_->rest_length_m(), model_->rest_length_rate_m_per_s(), model_->tension_n(), now);
  }
  if (recorder_ != nullptr) recorder_->record(stats_.sim_time_s(), *model_);
  if (hook_) hook_(*this);
}

void WorldStepper::apply_due_events() {
  const double now_s = stats_.sim_time_s();
  while (next_event_ < scenario_.events.size() && scenario_.events[next_event_].time_s <= now_s + 1e-9) {
    apply(scenario_.events[next_event_++]);
  }
}

void WorldStepper::apply(const ScenarioEvent& ev) {
  if (ev.fault == FaultKind::cut_dds || ev.fault == FaultKind::restore_dds) return apply_dds_link(ev);
  const int e = ev.endcap;
  Endcap& ec = endcaps_[e];
  const std::int64_t now = now_device_ns();
  const auto motors = [&] {
    std::vector<std::size_t> m;
    for (std::size_t i = 0; i < ec.devices.motor_count(); ++i) {
      if (ev.params.motor < 0 || static_cast<std::size_t>(ev.params.motor) == i) m.push_back(i);
    }
    if (m.empty()) throw HilError(ev.describe() + ": end cap has no motor " + std::to_string(ev.params.motor));
    return m;
  };
  const auto until = [&] {
    return ev.params.duration_s > 0.0
               ? stats_.steps + static_cast<std::int64_t>(std::llround(ev.params.duration_s / stats_.dt_s))
               : std::int64_t{-1};
  };
  switch (ev.fault) {
    case FaultKind::drive_fault:
      for (std::size_t m : motors()) ec.devices.fault_drive(m, ev.params.code, ev.params.release, now, out_);
      for (const CanFrame& f : out_) hub_.queue(e, f);  // the EMCY, ahead of this tick's PDOs
      out_.clear();
      break;
    case FaultKind::drive_silent:
      for (std::size_t m : motors()) ec.devices.silence_drive(m, true);
      break;
    case FaultKind::release_spool:
      for (std::size_t m : motors()) ec.devices.release_spool(m);
      break;
    case FaultKind::seize_spool:
      for (std::size_t m : motors()) ec.devices.seize_spool(m);
      break;
    case FaultKind::load_cell_stuck: ec.devices.set_load_cell_stuck(true); break;
    case FaultKind::load_cell_drift: ec.devices.start_load_cell_drift(ev.params.n_per_s, now); break;
    case FaultKind::drop_frames:
      hub_.set_drop(e, ev.params.probability);
      frame_faults_.push_back({e, false, until()});
      break;
    case FaultKind::corrupt_frames:
      hub_.set_corrupt(e, ev.params.probability, ev.params.corrupt_kind);
      frame_faults_.push_back({e, true, until()});
      break;
    case FaultKind::kill_endcap:
      processes_.kill(e);
      hub_.forget_version(e);
      ec.state = EndcapState::down;
      ec.devices.on_connection_lost();
      break;
    case FaultKind::restart_endcap:
      if (ec.state == EndcapState::live) processes_.kill(e);
      ec.devices.on_connection_lost();
      hub_.forget_version(e);
      processes_.restart(e);
      ec.state = EndcapState::waiting_process;
      ec.first_answer_pending = true;
      break;
    case FaultKind::reboot_drive:
      for (std::size_t m : motors()) ec.devices.reboot_drive(m, now, out_);
      for (const CanFrame& f : out_) hub_.queue(e, f);  // the boot-up, ahead of this tick's PDOs
      out_.clear();
      break;
    case FaultKind::reboot_load_cell:
      ec.devices.reboot_load_cell(now, out_);
      for (const CanFrame& f : out_) hub_.queue(e, f);
      out_.clear();
      break;
    case FaultKind::hang_loop:
    case FaultKind::stop_endcap:
      if (const std::string why = processes_.freeze(e, ev.fault == FaultKind::hang_loop); !why.empty()) {
        log_.push_back(ev.describe() + ": not done: " + why);
        return;
      }
      ec.awaited = false;
      break;
    case FaultKind::cut_dds:
    case FaultKind::restore_dds: break;  // apply_dds_link
  }
  log_.push_back(ev.describe());
}

// endcap -1: every end cap, i.e. the host's own link.
void WorldStepper::apply_dds_link(const ScenarioEvent& ev) {
  std::string skipped;
  for (int e = 0; e < endcap_count(); ++e) {
    if (ev.endcap >= 0 && e != ev.endcap) continue;
    const std::string why = processes_.set_dds_link(e, ev.fault == FaultKind::restore_dds);
    if (!why.empty()) skipped += (skipped.empty() ? "" : "; ") + ("end cap " + std::to_string(e) + ": " + why);
  }
  log_.push_back(ev.describe() + (skipped.empty() ? "" : ": not done for " + skipped));
}

void WorldStepper::update_frame_faults() {
  for (auto it = frame_faults_.begin(); it != frame_faults_.end();) {
    if (it->until_step >= 0 && stats_.steps >= it->until_step) {
      if (it->corrupt) {
        hub_.set_corrupt(it->endcap, 0.0, CorruptKind::frame);
      } else {
        hub_.set_drop(it->endcap, 0.0);
      }
      it = frame_faults_.erase(it);
    } else {
      ++it;
    }
  }
}

std::string WorldStepper::boot_report() const {
  std::ostringstream s;
  s << "boot: not every end cap reached the start gate (drives switched on, asking for operation enabled) within "
    << ns_to_s(config_.boot_timeout_ns) << " s:";
  for (int e = 0; e < endcap_count(); ++e) {
    const Endcap& ec = endcaps_[e];
    if (ec.state == EndcapState::live && ec.devices.at_gate()) continue;
    s << " end cap " << e << " ";
    if (ec.state != EndcapState::live) {
      s << "has no bus socket";
    } else {
      for (std::size_t m = 0; m < ec.devices.motor_count(); ++m) {
        s << (m ? ", " : "") << "drive node " << static_cast<int>(ec.devices.drive_node(m)) << " "
          << to_string(ec.devices.drive(m).state());
      }
    }
    s << " (" << const_cast<EndcapProcesses&>(processes_).describe(e) << ");";
  }
  return s.str();
}

// Lockstep owns time: nothing moves while an end cap's program starts again, as
// nothing moves while one is slow to answer. The physics time the end cap misses is
// then the scenario's (from its kill to its restart, plus its bring-up in SYNC ticks),
// not however long the host takes to start a process, and a run with restarts is as
// reproducible as one without.
void WorldStepper::await_restarted() {
  const std::int64_t t0 = monotonic_ns();
  for (;;) {
    std::string waiting;
    for (int e = 0; e < endcap_count(); ++e) {
      Endcap& ec = endcaps_[e];
      if (ec.state != EndcapState::waiting_process) continue;
      if (processes_.listening(e)) {
        ec.state = EndcapState::live;
        ec.first_answer_pending = true;
      } else {
        waiting += " end cap " + std::to_string(e) + " (" + processes_.describe(e) + ");";
      }
    }
    if (waiting.empty()) return;
    if (stop_requested()) throw HilError("interrupted");
    for (int e = 0; e < endcap_count(); ++e) {
      if (endcaps_[e].state != EndcapState::waiting_process || !processes_.exited(e)) continue;
      throw HilError("lockstep: end cap " + std::to_string(e) +
                     "'s restarted program exited before it listened on its bus (physics step " +
                     std::to_string(stats_.steps) + "): " + processes_.describe(e));
    }
    if (monotonic_ns() - t0 > config_.boot_timeout_ns) {
      std::ostringstream why;
      why << "lockstep: a restarted program is not listening on its bus within " << ns_to_s(config_.boot_timeout_ns)
          << " s (physics step " << stats_.steps << "):" << waiting;
      throw HilError(why.str());
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

// Without this a program that fails at start (a bad config, a missing library) would
// cost the whole boot timeout and then be reported among the slow ones.
void WorldStepper::fail_on_exit() {
  const std::int64_t now = monotonic_ns();
  if (now - last_exit_check_ns_ < kAdmitCheckPeriodNs) return;
  last_exit_check_ns_ = now;
  for (int e = 0; e < endcap_count(); ++e) {
    if (!processes_.exited(e)) continue;
    throw HilError("boot: end cap " + std::to_string(e) + "'s program exited before the start gate: " +
                   processes_.describe(e));
  }
}

void WorldStepper::boot() {
  const std::int64_t t0 = monotonic_ns();
  for (Endcap& ec : endcaps_) {
    ec.devices.power_on(0, out_);
    out_.clear();  // nobody listens yet; the master resets communication anyway
    ec.devices.update_from_model(model_->rest_length_m(), model_->rest_length_rate_m_per_s(), model_->tension_n(), 0);
  }
  if (config_.mode == StepperMode::realtime) {
    boot_realtime();
  } else {
    for (;;) {
      admit_listening();
      if (all_at_gate()) break;
      fail_on_exit();
      if (monotonic_ns() - t0 > config_.boot_timeout_ns) throw HilError(boot_report());
      bool any_to_tick = false;
      for (const Endcap& ec : endcaps_) any_to_tick = any_to_tick || (ec.state == EndcapState::live && !ec.devices.at_gate());
      if (stop_requested()) throw HilError("interrupted");
      if (!any_to_tick) {
        std::this_thread::sleep_for(std::chrono::microseconds(200));
        continue;
      }
      lockstep_tick(false);
      ++stats_.boot_ticks;
    }
  }
  stats_.boot_wall_s = ns_to_s(monotonic_ns() - t0);
}

void WorldStepper::start() {
  if (!all_at_gate() && !(config_.mode == StepperMode::realtime && config_.realtime_gate_on_arrival)) {
    throw HilError("start() before every end cap waits at the start gate");
  }
  for (Endcap& ec : endcaps_) ec.devices.release_gate();
  started_ = true;
  start_centre_ = model_->centre_m();
}

void WorldStepper::run(double duration_s) {
  if (!started_) throw HilError("run() before start()");
  if (config_.mode == StepperMode::realtime) return run_realtime(duration_s);
  const auto steps = static_cast<std::int64_t>(std::llround(duration_s / stats_.dt_s));
  const std::int64_t t0 = monotonic_ns();
  for (std::int64_t i = 0; i < steps; ++i) {
    apply_due_events();
    update_frame_faults();
    await_restarted();
    lockstep_tick(true);
  }
  stats_.run_wall_s = ns_to_s(monotonic_ns() - t0);
}

// --- real time -------------------------------------------------------------------

void WorldStepper::boot_realtime() {
  const std::int64_t t0 = monotonic_ns();
  std::int64_t next = t0 + period_ns_;
  for (;;) {
    while (monotonic_ns() < next) {
      rx_.clear();
      if (hub_.receive(rx_, next) > 0) route(rx_);
    }
    if (stop_requested()) throw HilError("interrupted");
    next += period_ns_;
    ++ticks_;
    ++stats_.boot_ticks;
    admit_listening();
    for (int e = 0; e < endcap_count(); ++e) {
      if (endcaps_[e].state != EndcapState::live) continue;
      endcaps_[e].devices.tick(now_device_ns(), out_);
      for (const CanFrame& f : out_) hub_.queue(e, f);
      out_.clear();
    }
    hub_.flush();
    if (all_at_gate()) return;
    if (config_.realtime_gate_on_arrival) {
      bool all_enabled = true;
      for (Endcap& ec : endcaps_) {
        if (ec.state == EndcapState::live && ec.devices.at_gate()) ec.devices.release_gate();
        all_enabled = all_enabled && ec.state == EndcapState::live && ec.devices.any_follows();
      }
      if (all_enabled) return;
    }
    fail_on_exit();
    if (monotonic_ns() - t0 > config_.boot_timeout_ns) throw HilError(boot_report());
  }
}

// run_realtime: world_stepper_realtime.cpp

}  // namespace tensegrity::hil
