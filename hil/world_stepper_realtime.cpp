// SPDX-License-Identifier: Apache-2.0
// WorldStepper::run: real-time mode. The end caps run their own 1 kHz timers and
// send targets and SYNC; the stepper keeps physics on the wall clock.
//
// One wake-up per step: the stepper sleeps to the step's absolute deadline
// (pacer.hpp), then serves in one go every frame the end caps sent since the last
// step (targets latched, SYNCs answered with the sensor PDOs, SDO and NMT
// answered), sends everything in one flush and steps physics. Serving at the
// tick rather than at each arrival changes nothing the plant or an end cap can
// tell: every target that arrived before the deadline drives this step either
// way, and a SYNC sent at t is answered with the state after the step before t
// either way, before the end cap's next cycle at t + 1 period (unless the stepper
// itself is late). It saves the stepper a wake-up per end cap and period.
#include <algorithm>
#include <cmath>
#include <string>

#include "hil/hil_error.hpp"
#include "hil/lateness.hpp"
#include "hil/pacer.hpp"
#include "hil/world_stepper.hpp"

namespace tensegrity::hil {

void WorldStepper::run_realtime(double duration_s) {
  const auto steps = static_cast<std::int64_t>(std::llround(duration_s / stats_.dt_s));
  const ScopedTimerSlack slack(1);
  LatenessStats lateness(period_ns_, period_ns_ / 2);
  const std::int64_t t0 = monotonic_ns();
  for (std::int64_t i = 0; i < steps; ++i) {
    const std::int64_t deadline = t0 + i * period_ns_;
    pace_until(deadline, config_.spin_ns);
    if (stop_requested()) throw HilError("interrupted");
    lateness.add(monotonic_ns() - deadline);
    for (;;) {
      rx_.clear();
      if (hub_.receive(rx_, 0) == 0) break;
      serve(rx_);
    }
    apply_due_events();
    update_frame_faults();
    admit_listening();
    for (int e = 0; e < endcap_count(); ++e) {
      Endcap& ec = endcaps_[e];
      if (ec.state != EndcapState::live) continue;
      // The end cap's bring-up would time out at the gate (2 s of its own clock),
      // so in real time a rejoining end cap is let through at once: not in phase.
      if (ec.devices.at_gate()) {
        ec.devices.release_gate();
        ++stats_.rejoins;
        note("end cap " + std::to_string(e) + " enabled again (real time: not phase-aligned)");
      }
      ec.devices.tick(now_device_ns(), out_);
      for (const CanFrame& f : out_) hub_.queue(e, f);
      out_.clear();
    }
    hub_.flush();
    physics_step();
    ++ticks_;
  }
  stats_.run_wall_s = static_cast<double>(monotonic_ns() - t0) * 1e-9;
  stats_.lateness = lateness.summary();
  stats_.late_steps = stats_.lateness.late_steps;
  stats_.max_lateness_s = static_cast<double>(stats_.lateness.max_ns) * 1e-9;
}

}  // namespace tensegrity::hil
