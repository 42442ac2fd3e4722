// SPDX-License-Identifier: Apache-2.0
#include "hil/endcap_config.hpp"

#include <string>

#include "hil/endcap_devices.hpp"

namespace tensegrity::hil {

fw::app::EndcapAppConfig endcap_config(const LauncherConfig& lc, int motors, std::uint16_t port,
                                       const std::filesystem::path& store) {
  fw::app::EndcapAppConfig c;
  // batch: a cycle's frames in one datagram (docs/design/udp-can.md, version 2).
  c.bus = "udp:127.0.0.1:" + std::to_string(lc.hub_port) + ",bind=127.0.0.1:" + std::to_string(port) + ",batch";
  c.motor_count = static_cast<std::uint32_t>(motors);
  for (int m = 0; m < motors; ++m)
    c.drive_node_ids[static_cast<std::size_t>(m)] = kDriveNodeIds[static_cast<std::size_t>(m)];
  c.load_cell_node_id = kLoadCellNodeId;
  c.spool_radius_m = lc.spool.spool_radius_m;
  c.counts_per_rev = lc.spool.counts_per_rev;
  c.initial_rest_length_m = lc.spool.initial_rest_length_m;
  c.limits = lc.limits;
  c.storage_dir = store;
  c.loop_period_ns = lc.loop_period_ns;
  c.mode = lc.mode == StepperMode::realtime ? fw::app::LoopMode::realtime : fw::app::LoopMode::lockstep;
  c.drive_heartbeat_timeout_s = 0.1;
  c.load_cell_heartbeat_timeout_s = 0.1;
  c.load_cell_sample_timeout_s = 0.02;
  // Real time on a shared 2-core host: an end cap's loop (or the emulator, whose
  // catch-up ticks then pass without frames) was seen to stall beyond the default
  // 50 ms while twelve programs start, and its drives then quick-stop it at boot;
  // and a restarted end cap latched stale_position on a 20 ms gap in a CI run. Each
  // side's silence timeouts are then the host's stall bound, not the bus's.
  // Lockstep keeps the defaults: everything there runs in device time.
  if (lc.mode == StepperMode::realtime) {
    c.drive_consumer_heartbeat_s = kRealtimeConsumerHeartbeatS;
    c.drive_heartbeat_timeout_s = kRealtimeSilenceTimeoutS;
    c.load_cell_heartbeat_timeout_s = kRealtimeSilenceTimeoutS;
    c.load_cell_sample_timeout_s = kRealtimeSilenceTimeoutS;
    c.drive_position_timeout_s = kRealtimeSilenceTimeoutS;
  }
  c.start_on_boot = false;
  c.stats_log_period_s = 10.0;
  return c;
}

}  // namespace tensegrity::hil
