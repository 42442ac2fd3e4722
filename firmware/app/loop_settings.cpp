// SPDX-License-Identifier: Apache-2.0
// The end cap's config (seconds, as people write them) -> the loop's settings
// (nanoseconds and node ids, as the loop and the CANopen master use them).
#include <algorithm>
#include <cmath>

#include "firmware/app/control_loop.hpp"
#include "core/table.hpp"

namespace tensegrity::fw::app {
LoopSettings make_loop_settings(const EndcapAppConfig& c) {
  LoopSettings s;
  s.core.motor_count = c.motor_count;
  s.core.limits = c.limits;
  s.core.initial_rest_length_m = c.initial_rest_length_m;
  s.master.drive_node_id = c.drive_node_ids[0];
  s.master.drive_count = static_cast<std::uint8_t>(c.motor_count);
  for (std::uint32_t i = 1; i < c.motor_count; ++i) s.master.extra_drive_node_ids[i - 1] = c.drive_node_ids[i];
  s.master.load_cell_node_id = c.load_cell_node_id;
  s.master.use_load_cell = c.use_load_cell;
  s.master.drive_heartbeat_timeout_ns = core::seconds_to_ns(c.drive_heartbeat_timeout_s);
  s.master.load_cell_heartbeat_timeout_ns = core::seconds_to_ns(c.load_cell_heartbeat_timeout_s);
  // Each node beats five times per heartbeat timeout (the shorter of the two), so
  // one late frame is never a loss and a node leaving operational shows within a
  // fifth of it; bring-up writes this to every node's 0x1017.
  const double node_period_ms =
      std::floor(std::min(c.drive_heartbeat_timeout_s, c.load_cell_heartbeat_timeout_s) * 1e3 / 5.0);
  s.master.node_heartbeat_period_ms = static_cast<std::uint16_t>(std::clamp(node_period_ms, 1.0, 65535.0));
  s.master.spool = c.spool();
  s.master.master_node_id = c.endcap_node_id;
  s.master.producer_heartbeat_period_ns = core::seconds_to_ns(c.endcap_heartbeat_s);
  s.master.drive_consumer_heartbeat_ms = static_cast<std::uint16_t>(std::llround(c.drive_consumer_heartbeat_s * 1e3));
  s.master.drive_abort_connection = c.drive_abort_connection;
  s.safety.drive_position_timeout_ns = core::seconds_to_ns(c.drive_position_timeout_s);
  s.safety.motor_count = c.motor_count;
  s.safety.use_load_cell = c.use_load_cell;
  s.safety.load_cell_sample_timeout_ns = core::seconds_to_ns(c.load_cell_sample_timeout_s);
  s.mode = c.mode;
  s.period_ns = c.loop_period_ns;
  s.master.sync_period_ns = c.loop_period_ns;
  s.start_on_boot = c.start_on_boot;
  // The drives stop themselves once no heartbeat came for their consumer time,
  // and the last one may have left a producer period before the loop stopped.
  const std::int64_t consumer_ns = std::int64_t{s.master.drive_consumer_heartbeat_ms} * 1'000'000;
  s.stall_limit_ns = consumer_ns > 0 ? std::max(consumer_ns - s.master.producer_heartbeat_period_ns, s.period_ns) : 0;
  const double window = std::ceil(c.stats_log_period_s * 1e9 / static_cast<double>(c.loop_period_ns));
  s.stats_window_cycles = window < 1.0 ? 1 : static_cast<std::uint64_t>(window);
  return s;
}

}  // namespace tensegrity::fw::app
