// SPDX-License-Identifier: Apache-2.0
// WorldStepper::hold: the phase between the start gate and physics step 0 in which
// a provisioner talks to the running end caps over DDS (start_handshake.hpp), and
// serve_until, the real-time shutdown.
#include <algorithm>

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
  const std::int64_t t0 = source_.now_ns();
  if (config_.mode == StepperMode::realtime) {
    hold_realtime(handshake, t0 + timeout_ns);
  } else {
    hold_lockstep(handshake, t0 + timeout_ns);
  }
  start_frame_ = frame_now(*model_, faces_, start_face_);
  stats_.hold_wall_s = static_cast<double>(source_.now_ns() - t0) * 1e-9;
}

void WorldStepper::hold_lockstep(StartHandshake& handshake, std::int64_t deadline_ns) {
  source_.begin_periods(source_.now_ns());
  FrozenTick last;
  int attempts = 0;
  for (;;) {
    source_.check_stop();
    if (auto d = handshake.decision(0); d && d->failed) throw HilError(d->reason);
    const bool clean = stats_.hold_ticks > 0 && last.answered_ns - last.sent_ns <= kCleanTickNs;
    if (handshake.freeze_requested() && (clean || attempts >= kMaxFreezeAttempts)) {
      return freeze_and_start(handshake, deadline_ns, last);
    }
    if (handshake.freeze_requested()) ++attempts;
    if (source_.now_ns() > deadline_ns) {
      throw HilError("hold: the provisioner did not start the run within the hold timeout");
    }
    // Paced to the wall clock: the end caps' loop clocks then advance with the
    // host's clock while the DDS side works, and the CPU stays free for it.
    source_.clock().sleep_until(source_.period_end_ns(), 0);
    source_.advance_period(true);
    roster_.admit_listening(source_.now_ns());
    last.sent_ns = source_.now_ns();
    lockstep_tick(false);
    last.answered_ns = source_.now_ns();
    ++stats_.hold_ticks;
  }
}

// No more SYNCs until the provisioner places the start; then ticks 1 .. k-1
// after the freeze, still without physics: tick k is physics step 0 (run()).
void WorldStepper::freeze_and_start(StartHandshake& handshake, std::int64_t deadline_ns, const FrozenTick& last) {
  handshake.frozen(last);
  for (;;) {
    source_.check_stop();
    if (source_.now_ns() > deadline_ns) throw HilError("hold: no start decision within the hold timeout");
    const auto d = handshake.decision(std::min(deadline_ns, source_.now_ns() + kDecisionPollNs));
    if (!d) continue;
    if (d->failed) throw HilError(d->reason);
    for (std::int64_t i = 1; i < d->after_ticks; ++i) {
      roster_.admit_listening(source_.now_ns());
      lockstep_tick(false);
      ++stats_.hold_ticks;
    }
    return;
  }
}

void WorldStepper::hold_realtime(StartHandshake& handshake, std::int64_t deadline_ns) {
  source_.begin_periods(source_.now_ns() + source_.period_ns());
  for (;;) {
    const auto d = handshake.decision(0);
    if (d && d->failed) throw HilError(d->reason);
    const std::int64_t next = source_.period_end_ns();
    serve_frames_until(d && d->at_ns < next ? d->at_ns : next);
    source_.check_stop();
    if (d && source_.now_ns() >= d->at_ns) return;  // run() steps physics from now on
    if (source_.now_ns() > deadline_ns) {
      throw HilError("hold: the provisioner did not start the run within the hold timeout");
    }
    source_.advance_period(false);
    idle_realtime_tick();
    ++stats_.hold_ticks;
  }
}

void WorldStepper::serve_until(const std::function<bool()>& done, std::int64_t timeout_ns) {
  if (config_.mode != StepperMode::realtime) return;
  const std::int64_t deadline = source_.now_ns() + timeout_ns;
  source_.begin_periods(source_.now_ns() + source_.period_ns());
  while (!done() && source_.now_ns() < deadline) {
    serve_frames_until(source_.period_end_ns());
    source_.advance_period(false);
    idle_realtime_tick();
  }
}

// Once per period, as in the run (world_stepper_realtime.cpp): sleep to the
// period's end, then serve everything the end caps sent since. Serving each
// arrival at once woke this SCHED_FIFO thread up to twelve times a period and
// left the end caps' DDS threads too little: a real-time run's DDS bring-up took
// 2-5 s and its upload 200-650 ms, against 1.2-2.2 s and 40-110 ms served per
// period (seven alternating runs each, docs/design/hil-performance.md).
void WorldStepper::serve_frames_until(std::int64_t until_ns) {
  source_.clock().sleep_until(until_ns, 0);
  for (;;) {
    rx_.clear();
    if (hub_.receive(rx_, 0) == 0) break;
    serve(rx_);
  }
  hub_.flush();
}

// One real-time period without physics: heartbeats and fault reactions of every
// live end cap's devices (their PDOs answer the end caps' own SYNCs in serve()).
void WorldStepper::idle_realtime_tick() {
  ++ticks_;
  roster_.admit_listening(source_.now_ns());
  for (int e = 0; e < endcap_count(); ++e) {
    if (!roster_.live(e)) continue;
    if (roster_.devices(e).at_gate()) roster_.devices(e).release_gate();
    send_tick(e, false);
  }
  hub_.flush();
}

}  // namespace tensegrity::hil
