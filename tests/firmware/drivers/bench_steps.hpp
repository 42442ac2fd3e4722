// SPDX-License-Identifier: Apache-2.0
// Steps the drivers' tests share on a Bench: bringing it up as an end cap does, and
// asking what the master reported.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "bench.hpp"

namespace tensegrity::fw::canopen {

inline bool has_event(const std::vector<MasterEvent>& events, MasterEventKind kind, std::uint8_t node) {
  return std::any_of(events.begin(), events.end(),
                     [&](const MasterEvent& e) { return e.kind == kind && e.node_id == node; });
}

// Power on, start both nodes, enable the drive: the state an end cap runs in.
inline void bring_up(sim::Bench& b, int max_cycles = 300) {
  b.power_on();
  b.master.start_bring_up(b.clock.now_ns());
  ASSERT_TRUE(b.run_until([&] { return b.master.bring_up_step() == BringUpStep::done; }, max_cycles))
      << to_string(b.master.bring_up_step()) << " " << b.master.bring_up_failure();
}

}  // namespace tensegrity::fw::canopen
