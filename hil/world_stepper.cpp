// SPDX-License-Identifier: Apache-2.0
#include "hil/world_stepper.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "firmware/drivers/pdo_codec.hpp"
#include "hil/hil_error.hpp"
#include "hil/loop_rate.hpp"

namespace tensegrity::hil {

namespace {
constexpr std::int64_t kIdlePollNs = 200'000;  // boot: nobody to tick, look again this much later

double ns_to_s(std::int64_t ns) { return static_cast<double>(ns) * 1e-9; }
}  // namespace

const char* to_string(StepperMode mode) { return mode == StepperMode::lockstep ? "lockstep" : "realtime"; }

double StepperStats::sim_time_s() const { return static_cast<double>(steps) * dt_s; }

WorldStepper::WorldStepper(const sim::Robot& robot, const sim::ModelState& start, UdpHub& hub,
                           EndcapProcesses& processes, const StepperConfig& config, Clock& clock, std::stop_token stop)
    : model_(std::make_unique<sim::Model>(robot, robot.time_step_s)),
      hub_(hub),
      config_(config),
      source_(clock, endcap_period_ns(robot), std::move(stop), config.answer_nap_fraction),
      roster_(robot, config.spool, config.mode == StepperMode::lockstep, processes),
      faults_({}, robot.time_step_s),
      fault_target_(roster_, hub) {
  model_->restore(start);
  stats_.dt_s = robot.time_step_s;
  preferred_.assign(model_->rest_length_m().begin(), model_->rest_length_m().end());
  faces_ = sim::hull_faces(robot);
  start_frame_ = frame_now(*model_, faces_, start_face_);
  out_.reserve(64);
  rx_.reserve(256);
}

sim::StartFrame frame_now(const sim::Model& model, const std::vector<sim::HullFace>& faces, std::vector<int>& face) {
  const std::vector<Eigen::Vector3d> nodes = model.node_positions();
  const sim::StartFrame frame = sim::start_frame(model.robot(), faces, nodes);
  face.clear();
  if (frame.face >= 0) face.assign(faces[frame.face].nodes.begin(), faces[frame.face].nodes.end());
  return frame;
}

sim::Travel WorldStepper::travel() const {
  const Eigen::Vector3d c = model_->centre_m();
  return sim::travel(start_frame_, {c.x(), c.y()});
}

void WorldStepper::note(const std::string& line) {
  std::ostringstream s;
  s << "t=" << stats_.sim_time_s() << " s: " << line;
  log_.push_back(s.str());
}

void WorldStepper::serve(const std::vector<UdpHub::Rx>& rx) {
  const std::int64_t now = now_device_ns();
  for (const UdpHub::Rx& r : rx) {
    roster_.devices(r.endcap).on_frame(r.frame, now, out_);
    for (const CanFrame& f : out_) hub_.queue(r.endcap, f);
    out_.clear();
  }
}

bool WorldStepper::receive(std::int64_t deadline_ns) {
  rx_.clear();
  if (hub_.receive(rx_, deadline_ns) == 0) return false;
  serve(rx_);
  hub_.flush();
  return true;
}

void WorldStepper::apply_faults() { faults_.apply_due(stats_.steps, now_device_ns(), fault_target_, log_); }

void WorldStepper::send_tick(int e, bool sync) {
  EndcapDevices& devices = roster_.devices(e);
  devices.tick(now_device_ns(), out_);
  if (sync) {
    devices.emit_sensors(out_);
    out_.push_back(fw::canopen::encode_sync(0));
  }
  for (const CanFrame& f : out_) hub_.queue(e, f);
  out_.clear();
}

// Paused at the start gate: no SYNC, so its time (and bring-up timeout) stands
// still. After the start it is let through at a period boundary: in phase.
bool WorldStepper::pass_gate(int e) {
  EndcapDevices& devices = roster_.devices(e);
  if (!devices.at_gate()) return true;
  const std::int64_t p = config_.phase_period_steps;
  if (!started_ || (p > 0 && stats_.steps % p != 0)) return false;
  devices.release_gate();
  ++stats_.rejoins;
  note("end cap " + std::to_string(e) + " enabled again (table time 0 at step " + std::to_string(stats_.steps) + ")");
  return true;
}

void WorldStepper::lockstep_tick(bool physics) {
  source_.check_stop();
  for (int e = 0; e < endcap_count(); ++e) {
    const bool ticked = roster_.live(e) && pass_gate(e);
    roster_.expect(e, ticked && roster_.awaited(e));  // a frozen one's bus runs on, unawaited
    if (!ticked) continue;
    send_tick(e, true);
    roster_.devices(e).clear_rpdo_marks();
  }
  Clock& clock = source_.clock();
  const std::int64_t t_send = clock.now_ns();
  hub_.flush();
  const std::int64_t t_wait = clock.now_ns();
  const bool first = roster_.first_answer_expected();
  const auto expect = !roster_.any_expected() ? TickSource::Expect::nothing
                      : first                 ? TickSource::Expect::first_answers
                                              : TickSource::Expect::usual;
  const std::int64_t waited =
      source_.barrier(*this, expect, first ? config_.first_answer_timeout_ns : config_.barrier_timeout_ns, ticks_,
                      started_ ? stats_.steps : -1);
  roster_.answered();
  stats_.max_barrier_wait_s = std::max(stats_.max_barrier_wait_s, ns_to_s(waited));
  const std::int64_t t_physics = clock.now_ns();
  if (physics) {
    physics_step();
    stats_.send_wall_s += ns_to_s(t_wait - t_send);
    stats_.barrier_wall_s += ns_to_s(t_physics - t_wait);
    stats_.physics_wall_s += ns_to_s(clock.now_ns() - t_physics);
  }
  ++ticks_;
}

void WorldStepper::physics_step() {
  const auto rest = model_->rest_length_m();
  for (int e = 0; e < endcap_count(); ++e) roster_.devices(e).preferred(rest, preferred_);
  try {
    model_->step(preferred_);
  } catch (const sim::ModelDiverged& e) {
    throw HilError(std::string("the model diverged at step ") + std::to_string(stats_.steps) + ": " + e.what());
  }
  ++stats_.steps;
  const std::int64_t now = (ticks_ + 1) * source_.period_ns();
  for (double t : model_->tension_n()) stats_.max_tension_n = std::max(stats_.max_tension_n, t);
  for (int e = 0; e < endcap_count(); ++e) {
    roster_.devices(e).update_from_model(model_->rest_length_m(), model_->rest_length_rate_m_per_s(),
                                         model_->tension_n(), now);
  }
  if (recorder_ != nullptr) recorder_->record(stats_.sim_time_s(), *model_);
  if (hook_) hook_(*this);
}

void WorldStepper::boot() {
  const std::int64_t t0 = source_.now_ns();
  for (int e = 0; e < endcap_count(); ++e) {
    roster_.devices(e).power_on(0, out_);
    out_.clear();  // nobody listens yet; the master resets communication anyway
    roster_.devices(e).update_from_model(model_->rest_length_m(), model_->rest_length_rate_m_per_s(),
                                         model_->tension_n(), 0);
  }
  if (config_.mode == StepperMode::realtime) {
    boot_realtime();
  } else {
    boot_lockstep();
  }
  stats_.boot_wall_s = ns_to_s(source_.now_ns() - t0);
}

void WorldStepper::boot_lockstep() {
  Clock& clock = source_.clock();
  const std::int64_t t0 = clock.now_ns();
  for (;;) {
    roster_.admit_listening(clock.now_ns());
    if (roster_.all_at_gate()) return;
    roster_.fail_on_exit(clock.now_ns());
    if (clock.now_ns() - t0 > config_.boot_timeout_ns) throw HilError(roster_.boot_report(config_.boot_timeout_ns));
    source_.check_stop();
    if (!roster_.any_to_tick()) {
      clock.sleep_until(clock.now_ns() + kIdlePollNs, 0);
      continue;
    }
    lockstep_tick(false);
    ++stats_.boot_ticks;
  }
}

void WorldStepper::start() {
  if (!roster_.all_at_gate() && !(config_.mode == StepperMode::realtime && config_.realtime_gate_on_arrival)) {
    throw HilError("start() before every end cap waits at the start gate");
  }
  for (int e = 0; e < endcap_count(); ++e) roster_.devices(e).release_gate();
  started_ = true;
  start_frame_ = frame_now(*model_, faces_, start_face_);
}

void WorldStepper::run(double duration_s) {
  if (!started_) throw HilError("run() before start()");
  const auto steps = static_cast<std::int64_t>(std::llround(duration_s / stats_.dt_s));
  const std::int64_t t0 = source_.now_ns();
  if (config_.mode == StepperMode::realtime) {
    run_realtime(steps);
  } else {
    run_lockstep(steps);
  }
  stats_.run_wall_s = ns_to_s(source_.now_ns() - t0);
}

void WorldStepper::run_lockstep(std::int64_t steps) {
  source_.limit_speed(config_.max_speed);
  for (std::int64_t i = 0; i < steps; ++i) {
    source_.pace_lockstep();
    apply_faults();
    roster_.await_restarted(source_.clock(), source_.stop_token(), config_.boot_timeout_ns, stats_.steps);
    lockstep_tick(true);
  }
}

}  // namespace tensegrity::hil
