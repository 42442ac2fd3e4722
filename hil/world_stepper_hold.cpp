// SPDX-License-Identifier: Apache-2.0
// WorldStepper::hold: the phase between the start gate and physics step 0 in which
// a provisioner talks to the running end caps over DDS (start_handshake.hpp).
#include <chrono>
#include <thread>

#include "hil/hil_error.hpp"
#include "hil/world_stepper.hpp"

namespace tensegrity::hil {

namespace {
// A freeze is honoured after a tick whose answers all came back within this long
// of its SYNC: each end cap's record of when it ran that tick is then within it,
// so the start time placed in the middle is within half a tick of every one.
constexpr std::int64_t kCleanTickNs = 600'000;
constexpr int kMaxFreezeAttempts = 200;
constexpr std::int64_t kDecisionPollNs = 10'000'000;
}  // namespace

void WorldStepper::hold(StartHandshake& handshake, std::int64_t timeout_ns) {
  if (!started_) throw HilError("hold() before start()");
  const std::int64_t t0 = monotonic_ns();
  if (config_.mode == StepperMode::realtime) {
    hold_realtime(handshake, t0 + timeout_ns);
  } else {
    hold_lockstep(handshake, t0 + timeout_ns);
  }
  start_centre_ = model_->centre_m();
  stats_.hold_wall_s = static_cast<double>(monotonic_ns() - t0) * 1e-9;
}

void WorldStepper::hold_lockstep(StartHandshake& handshake, std::int64_t deadline_ns) {
  std::int64_t next = monotonic_ns();
  FrozenTick last;
  int attempts = 0;
  for (;;) {
    if (stop_requested()) throw HilError("interrupted");
    if (auto d = handshake.decision(0); d && d->failed) throw HilError(d->reason);
    const bool clean = stats_.hold_ticks > 0 && last.answered_ns - last.sent_ns <= kCleanTickNs;
    if (handshake.freeze_requested() && (clean || attempts >= kMaxFreezeAttempts)) {
      handshake.frozen(last);
      for (;;) {
        if (stop_requested()) throw HilError("interrupted");
        if (monotonic_ns() > deadline_ns) throw HilError("hold: no start decision within the hold timeout");
        const auto d = handshake.decision(std::min(deadline_ns, monotonic_ns() + kDecisionPollNs));
        if (!d) continue;
        if (d->failed) throw HilError(d->reason);
        // Ticks 1 .. k-1 after the freeze: still no physics; tick k is physics step 0 (run()).
        for (std::int64_t i = 1; i < d->after_ticks; ++i) {
          admit_listening();
          lockstep_tick(false);
          ++stats_.hold_ticks;
        }
        return;
      }
    }
    if (handshake.freeze_requested()) ++attempts;
    if (monotonic_ns() > deadline_ns) throw HilError("hold: the provisioner did not start the run within the hold timeout");
    // Paced to the wall clock: the end caps' loop clocks then advance with the
    // host's clock while the DDS side works, and the CPU stays free for it.
    std::this_thread::sleep_until(std::chrono::steady_clock::time_point(std::chrono::nanoseconds(next)));
    next += period_ns_;
    const std::int64_t now = monotonic_ns();
    if (next < now) next = now;
    admit_listening();
    last.sent_ns = monotonic_ns();
    lockstep_tick(false);
    last.answered_ns = monotonic_ns();
    ++stats_.hold_ticks;
  }
}

void WorldStepper::hold_realtime(StartHandshake& handshake, std::int64_t deadline_ns) {
  std::int64_t next = monotonic_ns() + period_ns_;
  for (;;) {
    const auto d = handshake.decision(0);
    if (d && d->failed) throw HilError(d->reason);
    const std::int64_t until = d && d->at_ns < next ? d->at_ns : next;
    serve_frames_until(until);
    if (stop_requested()) throw HilError("interrupted");
    if (d && monotonic_ns() >= d->at_ns) return;  // run() steps physics from now on
    if (monotonic_ns() > deadline_ns) throw HilError("hold: the provisioner did not start the run within the hold timeout");
    next += period_ns_;
    idle_realtime_tick();
    ++stats_.hold_ticks;
  }
}

void WorldStepper::serve_until(const std::function<bool()>& done, std::int64_t timeout_ns) {
  if (config_.mode != StepperMode::realtime) return;
  const std::int64_t deadline = monotonic_ns() + timeout_ns;
  std::int64_t next = monotonic_ns() + period_ns_;
  while (!done() && monotonic_ns() < deadline) {
    serve_frames_until(next);
    next += period_ns_;
    idle_realtime_tick();
  }
}

void WorldStepper::serve_frames_until(std::int64_t until_ns) {
  while (monotonic_ns() < until_ns) {
    rx_.clear();
    if (hub_.receive(rx_, until_ns) > 0) route(rx_);
  }
}

// One real-time period without physics: heartbeats and fault reactions of every
// live end cap's devices (their PDOs answer the end caps' own SYNCs in route()).
void WorldStepper::idle_realtime_tick() {
  ++ticks_;
  admit_listening();
  for (int e = 0; e < endcap_count(); ++e) {
    Endcap& ec = endcaps_[e];
    if (ec.state != EndcapState::live) continue;
    if (ec.devices.at_gate()) ec.devices.release_gate();
    ec.devices.tick(now_device_ns(), out_);
    for (const CanFrame& f : out_) hub_.queue(e, f);
    out_.clear();
  }
  hub_.flush();
}

}  // namespace tensegrity::hil
