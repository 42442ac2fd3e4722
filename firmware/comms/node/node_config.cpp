// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/node/node_config.hpp"

#include <cmath>
#include <stdexcept>

#include "msgs/security.hpp"

namespace tensegrity::fw::comms {

const char* to_string(HostLossAction action) { return action == HostLossAction::stop ? "stop" : "continue"; }

HostLossAction parse_host_loss_action(const std::string& text) {
  if (text == "continue") return HostLossAction::continue_gait;
  if (text == "stop") return HostLossAction::stop;
  throw std::invalid_argument("host-loss action '" + text + "': expected 'continue' or 'stop'");
}

void validate(const EndcapNodeConfig& c) {
  auto positive = [](double v, const char* name, double max) {
    if (!std::isfinite(v) || v <= 0.0 || v > max) {
      throw std::invalid_argument(std::string(name) + " = " + std::to_string(v) +
                                  ": expected > 0 and <= " + std::to_string(max));
    }
  };
  // The robot's end caps, as the wire names them (its writers and its 12-bit masks).
  if (c.endcap_id < 0 || c.endcap_id >= msgs::kMaxEndcaps) {
    throw std::invalid_argument("endcap_id = " + std::to_string(c.endcap_id) + ": expected 0.." +
                                std::to_string(msgs::kMaxEndcaps - 1));
  }
  if (c.domain < 0 || c.domain > 232) {
    throw std::invalid_argument("domain = " + std::to_string(c.domain) + ": expected 0..232");
  }
  positive(c.telemetry_rate_hz, "telemetry_rate_hz", 1000.0);
  positive(c.heartbeat_rate_hz, "heartbeat_rate_hz", 100.0);
  positive(c.time_sync_interval_s, "time_sync_interval_s", 60.0);
  positive(c.host_timeout_s, "host_timeout_s", 3600.0);
  positive(c.host_boot_grace_s, "host_boot_grace_s", 3600.0);
  if (c.host_boot_grace_s < c.host_timeout_s) {
    throw std::invalid_argument("host_boot_grace_s = " + std::to_string(c.host_boot_grace_s) +
                                ": expected >= host_timeout_s (" + std::to_string(c.host_timeout_s) + ")");
  }
  positive(c.loop_ack_timeout_s, "loop_ack_timeout_s", 60.0);
  positive(c.command_max_age_s, "command_max_age_s", 3600.0);
  positive(c.loop_stall_timeout_s, "loop_stall_timeout_s", 60.0);
  // A host names the end caps it heard in the last 2 s: a shorter wait would churn.
  const double r = c.unheard_rejoin_s;
  if (!(r == 0.0 || (std::isfinite(r) && r >= 3.0 && r <= 3600.0))) {
    throw std::invalid_argument("unheard_rejoin_s = " + std::to_string(r) + ": expected 0 (never) or 3..3600");
  }
  if (c.start_grid_ns < 0) {
    throw std::invalid_argument("start_grid_ns = " + std::to_string(c.start_grid_ns) + ": expected >= 0");
  }
}

}  // namespace tensegrity::fw::comms
