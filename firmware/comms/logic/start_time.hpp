// SPDX-License-Identifier: Apache-2.0
// Where a start's host time falls on the control loop's clock. Pure: the node
// gives it the time-sync offset and the loop's last published cycle.
//
// host time -> node clock (minus the offset) -> loop clock: loop time advanced
// with the node's clock since the loop's last publish. A lockstep loop (time =
// SYNC count x period, owned by the emulator) has no fixed relation to the host
// clock; it holds only while the SYNCs pause, so there the start is placed a whole
// number of `grid_ns` steps after the loop's last cycle (the host time since that
// cycle, rounded half away from zero). A HIL that pauses its SYNCs and aims the
// start a whole number of grid steps after the last one gets every end cap on the
// same SYNC, as long as each end cap's mapping error stays under half a step.
#pragma once

#include <cstdint>
#include <optional>

namespace tensegrity::fw::comms {

// The loop's last publish: its loop time, and the node clock when it arrived.
struct LoopClockPoint {
  std::int64_t loop_time_ns = 0;
  std::int64_t local_ns = 0;
};

class StartTimeMapper {
 public:
  // grid_ns 0: a free-running loop (host time maps directly).
  explicit StartTimeMapper(std::int64_t grid_ns = 0) : grid_ns_(grid_ns < 0 ? 0 : grid_ns) {}

  // Loop time of `host_start_ns`, given offset = host - node clock. Nothing when an
  // input is outside the wire-time range (wire_time.hpp) or a step would overflow.
  std::optional<std::int64_t> map(std::int64_t host_start_ns, std::int64_t offset_ns, LoopClockPoint last) const;
  std::int64_t grid_ns() const { return grid_ns_; }

 private:
  std::int64_t grid_ns_;
};

// n / g rounded half away from zero (g > 0), without overflow for any n.
std::int64_t round_div(std::int64_t n, std::int64_t g);

}  // namespace tensegrity::fw::comms
