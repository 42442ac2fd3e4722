// SPDX-License-Identifier: Apache-2.0
// Where the stepper's ticks come from, on a clock it is given.
//
// Lockstep: a tick is released when every end cap it was sent to has answered
// (barrier()); the wait has a timeout whose error names who is missing. Before
// waiting on the socket it naps a fraction of the usual answer time
// (answer_nap.hpp), so most answers are queued when it looks.
//
// Real time: step k's deadline is the run's origin + k periods, absolute, so it
// never drifts (pace()); how late each step begins is counted (lateness.hpp).
// Between runs (the start's hold, the shutdown) periods are paced without
// counting (begin_periods(), advance_period()).
//
// Stop through the std::stop_token it is given: every wait ends with
// HilError("interrupted") once a stop is requested.
#pragma once

#include <cstdint>
#include <stop_token>
#include <string>

#include "hil/answer_nap.hpp"
#include "hil/clock.hpp"
#include "hil/lateness.hpp"

namespace tensegrity::hil {

// What a lockstep tick waits for (the stepper: its hub and its roster).
class TickAnswers {
 public:
  virtual ~TickAnswers() = default;
  // Every end cap the tick's SYNC went to has answered.
  virtual bool all_in() const = 0;
  // Receives and serves what arrives until `deadline_ns`; false if nothing came.
  virtual bool receive(std::int64_t deadline_ns) = 0;
  // When the latest answer arrived (kernel timestamp; 0: unknown), since forget_arrivals().
  virtual void forget_arrivals() = 0;
  virtual std::int64_t latest_arrival_ns() const = 0;
  // For the timeout's error: who is missing, e.g. " end cap 9 sent no RPDO1 ...;".
  virtual std::string missing() = 0;
};

class TickSource {
 public:
  TickSource(Clock& clock, std::int64_t period_ns, std::stop_token stop, double answer_nap_fraction);

  Clock& clock() const { return clock_; }
  std::int64_t now_ns() const { return clock_.now_ns(); }
  std::int64_t period_ns() const { return period_ns_; }
  // Throws HilError("interrupted") once a stop is requested.
  void check_stop() const;
  const std::stop_token& stop_token() const { return stop_; }

  // --- lockstep ---
  enum class Expect : std::uint8_t {
    nothing,        // no end cap got this tick
    first_answers,  // one is a program just (re)started: no nap, a longer timeout
    usual,
  };
  // Waits until `answers.all_in()`. Throws HilError after `timeout_ns`, naming the
  // tick (`step` < 0: during boot) and what is missing. Returns the wait.
  std::int64_t barrier(TickAnswers& answers, Expect expect, std::int64_t timeout_ns, std::int64_t tick,
                       std::int64_t step);

  // --- real time ---
  // Step k's deadline is origin_ns + k periods; lateness is counted from here on.
  void start_pacing(std::int64_t origin_ns);
  // Sleeps to step k's deadline (polling the last spin_ns), counts how late it
  // began; throws on a stop. Returns the lateness.
  std::int64_t pace(std::int64_t step, std::int64_t spin_ns);
  LatenessSummary lateness() const { return lateness_.summary(); }
  std::int64_t origin_ns() const { return origin_ns_; }

  // --- lockstep speed limit ---
  // Physics at most `speed` times real time (0: no limit), from now on: watched
  // live, a run flat out is fast-forward, and it leaves the viewer no CPU.
  void limit_speed(double speed);
  // Sleeps until the next tick may begin under the limit (at once without one).
  // After a stall the run catches up at most kSpeedCatchUpNs, not in one burst.
  void pace_lockstep();
  static constexpr std::int64_t kSpeedCatchUpNs = 100'000'000;

  // --- between runs ---
  // Periods paced without counting lateness, the first ending at `first_ns`.
  void begin_periods(std::int64_t first_ns) { period_end_ns_ = first_ns; }
  std::int64_t period_end_ns() const { return period_end_ns_; }
  // One period on. skip_missed: never in the past (lockstep, whose device time is
  // its SYNC count: a stall is not made up with a burst); otherwise missed
  // periods follow at once (real time: the devices' clock keeps to the wall's).
  void advance_period(bool skip_missed);

 private:
  Clock& clock_;
  std::int64_t period_ns_;
  std::stop_token stop_;
  AnswerNap nap_;
  LatenessStats lateness_;
  std::int64_t origin_ns_ = 0;
  std::int64_t period_end_ns_ = 0;
  std::int64_t min_tick_ns_ = 0;  // lockstep: 0, no speed limit
  std::int64_t next_tick_ns_ = 0;
};

}  // namespace tensegrity::hil
