// SPDX-License-Identifier: Apache-2.0
// WorldStepper in real time: boot and run. The end caps run their own 1 kHz
// timers and send targets and SYNC; the stepper keeps physics on the wall clock.
//
// One wake-up per step: the stepper sleeps to the step's absolute deadline
// (TickSource::pace), then serves in one go every frame the end caps sent since the
// last step (targets latched, SYNCs answered with the sensor PDOs, SDO and NMT
// answered), sends everything in one flush and steps physics. Serving at the
// tick rather than at each arrival changes nothing the plant or an end cap can
// tell: every target that arrived before the deadline drives this step either
// way, and a SYNC sent at t is answered with the state after the step before t
// either way, before the end cap's next cycle at t + 1 period (unless the stepper
// itself is late). It saves the stepper a wake-up per end cap and period.
#include <string>

#include "hil/hil_error.hpp"
#include "hil/pacer.hpp"
#include "hil/world_stepper.hpp"

namespace tensegrity::hil {

void WorldStepper::boot_realtime() {
  const std::int64_t t0 = source_.now_ns();
  source_.begin_periods(t0 + source_.period_ns());
  for (;;) {
    serve_frames_until(source_.period_end_ns());
    source_.check_stop();
    source_.advance_period(false);
    ++ticks_;
    ++stats_.boot_ticks;
    roster_.admit_listening(source_.now_ns());
    for (int e = 0; e < endcap_count(); ++e) {
      if (roster_.live(e)) send_tick(e, false);
    }
    hub_.flush();
    if (roster_.all_at_gate()) return;
    if (config_.realtime_gate_on_arrival && roster_.release_arrived()) return;
    roster_.fail_on_exit(source_.now_ns());
    if (source_.now_ns() - t0 > config_.boot_timeout_ns) throw HilError(roster_.boot_report(config_.boot_timeout_ns));
  }
}

void WorldStepper::run_realtime(std::int64_t steps) {
  const ScopedTimerSlack slack(1);
  source_.start_pacing(source_.now_ns());
  for (std::int64_t i = 0; i < steps; ++i) {
    source_.pace(i, config_.spin_ns);
    for (;;) {
      rx_.clear();
      if (hub_.receive(rx_, 0) == 0) break;
      serve(rx_);
    }
    apply_faults();
    roster_.admit_listening(source_.now_ns());
    for (int e = 0; e < endcap_count(); ++e) {
      if (!roster_.live(e)) continue;
      // The end cap's bring-up would time out at the gate (2 s of its own clock),
      // so in real time a rejoining end cap is let through at once: not in phase.
      if (roster_.devices(e).at_gate()) {
        roster_.devices(e).release_gate();
        ++stats_.rejoins;
        note("end cap " + std::to_string(e) + " enabled again (real time: not phase-aligned)");
      }
      send_tick(e, false);
    }
    hub_.flush();
    physics_step();
    ++ticks_;
  }
  stats_.lateness = source_.lateness();
  stats_.late_steps = stats_.lateness.late_steps;
  stats_.max_lateness_s = static_cast<double>(stats_.lateness.max_ns) * 1e-9;
}

}  // namespace tensegrity::hil
