// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/logic/start_time.hpp"

#include "firmware/comms/wire/wire_time.hpp"

namespace tensegrity::fw::comms {

std::int64_t round_div(std::int64_t n, std::int64_t g) {
  const std::int64_t q = n / g;
  const std::int64_t r = n % g;  // same sign as n
  // |r| >= g - |r| <=> 2|r| >= g, written so that nothing overflows.
  if (r >= 0 ? r >= g - r : -r >= g + r) return n >= 0 ? q + 1 : q - 1;
  return q;
}

std::optional<std::int64_t> StartTimeMapper::map(std::int64_t host_start_ns, std::int64_t offset_ns,
                                                 LoopClockPoint last) const {
  // The offset is a difference of two clocks: within +-2^62 when both are valid.
  if (!valid_wire_time(host_start_ns) || offset_ns < -kMaxWireTimeNs || offset_ns > kMaxWireTimeNs) {
    return std::nullopt;
  }
  const auto local = checked_sub(host_start_ns, offset_ns);
  if (!local) return std::nullopt;
  const auto since_last_cycle = checked_sub(*local, last.local_ns);
  if (!since_last_cycle) return std::nullopt;
  if (grid_ns_ == 0) return checked_add(last.loop_time_ns, *since_last_cycle);
  const auto step_ns = checked_mul(round_div(*since_last_cycle, grid_ns_), grid_ns_);
  if (!step_ns) return std::nullopt;
  return checked_add(last.loop_time_ns, *step_ns);
}

}  // namespace tensegrity::fw::comms
