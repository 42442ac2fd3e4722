// SPDX-License-Identifier: Apache-2.0
// How late the real-time stepper begins its steps. A step's deadline is absolute
// (run start + k periods); it begins when the stepper stops waiting and starts
// serving the buses and the physics step. Late: began more than kLateAfter
// (half a period) after its deadline, i.e. nearer the next tick than its own.
// Deadlines never move, so one stall of d makes about d / period steps in a row
// late (they run back to back until physics is on time again): an episode.
// Fixed buckets, no allocation after construction.
#pragma once

#include <cstdint>

#include "core/histogram.hpp"

namespace tensegrity::hil {

struct LatenessSummary {
  std::int64_t steps = 0;
  std::int64_t late_steps = 0;     // began > late_after_ns after the deadline
  std::int64_t late_episodes = 0;  // runs of consecutive late steps (one stall each)
  std::int64_t missed_steps = 0;   // began a whole period or more after the deadline
  std::int64_t late_after_ns = 0;
  std::int64_t p50_ns = 0, p99_ns = 0, p999_ns = 0, max_ns = 0;
  // Sum over episodes of the first late step's lateness: how long the stepper was
  // kept from running, to set beside the hypervisor's steal time over the run.
  std::int64_t stalled_ns = 0;
};

class LatenessStats {
 public:
  LatenessStats(std::int64_t period_ns, std::int64_t late_after_ns)
      : period_ns_(period_ns), late_after_ns_(late_after_ns) {}

  // Returns whether this step is late.
  bool add(std::int64_t lateness_ns) noexcept;
  LatenessSummary summary() const noexcept;

 private:
  std::int64_t period_ns_;
  std::int64_t late_after_ns_;
  core::FixedHistogram<10'000, 2'000> histogram_;  // 10 us buckets to 20 ms
  std::int64_t late_ = 0, episodes_ = 0, missed_ = 0, stalled_ns_ = 0;
  bool previous_late_ = false;
};

}  // namespace tensegrity::hil
