// SPDX-License-Identifier: Apache-2.0
#include "hil/tick_source.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "hil/hil_error.hpp"

namespace tensegrity::hil {

TickSource::TickSource(Clock& clock, std::int64_t period_ns, std::stop_token stop, double answer_nap_fraction)
    : clock_(clock),
      period_ns_(period_ns),
      stop_(std::move(stop)),
      nap_(answer_nap_fraction),
      lateness_(period_ns, period_ns / 2) {}

void TickSource::check_stop() const {
  if (stop_.stop_requested()) throw HilError("interrupted");
}

std::int64_t TickSource::barrier(TickAnswers& answers, Expect expect, std::int64_t timeout_ns, std::int64_t tick,
                                 std::int64_t step) {
  const std::int64_t start = clock_.now_ns();
  const std::int64_t deadline = start + timeout_ns;
  answers.forget_arrivals();
  if (expect == Expect::usual) clock_.sleep_until(start + nap_.nap_ns(), 0);
  while (!answers.all_in()) {
    if (!answers.receive(deadline) && clock_.now_ns() >= deadline) {
      std::ostringstream why;
      why << "lockstep barrier: no drive targets within " << static_cast<double>(timeout_ns) * 1e-9
          << " s of the SYNC of tick " << tick
          << (step >= 0 ? " (physics step " + std::to_string(step) + ")" : std::string(" (boot)")) << ":"
          << answers.missing();
      throw HilError(why.str());
    }
  }
  const std::int64_t end = clock_.now_ns();
  if (expect != Expect::nothing)
    nap_.observe((answers.latest_arrival_ns() > 0 ? answers.latest_arrival_ns() : end) - start);
  return end - start;
}

void TickSource::start_pacing(std::int64_t origin_ns) {
  origin_ns_ = origin_ns;
  lateness_ = LatenessStats(period_ns_, period_ns_ / 2);
}

std::int64_t TickSource::pace(std::int64_t step, std::int64_t spin_ns) {
  const std::int64_t deadline = origin_ns_ + step * period_ns_;
  clock_.sleep_until(deadline, spin_ns);
  check_stop();
  const std::int64_t late = clock_.now_ns() - deadline;
  lateness_.add(late);
  return late;
}

void TickSource::limit_speed(double speed) {
  min_tick_ns_ = speed > 0.0 ? static_cast<std::int64_t>(std::llround(static_cast<double>(period_ns_) / speed)) : 0;
  next_tick_ns_ = clock_.now_ns();
}

void TickSource::pace_lockstep() {
  if (min_tick_ns_ == 0) return;
  clock_.sleep_until(next_tick_ns_, 0);
  check_stop();
  next_tick_ns_ = std::max(next_tick_ns_ + min_tick_ns_, clock_.now_ns() - kSpeedCatchUpNs);
}

void TickSource::advance_period(bool skip_missed) {
  period_end_ns_ += period_ns_;
  if (skip_missed) period_end_ns_ = std::max(period_end_ns_, clock_.now_ns());
}

}  // namespace tensegrity::hil
