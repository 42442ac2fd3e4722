// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/logic/command_wire.hpp"

namespace tensegrity::fw::comms {

CommandSample to_sample(const tensegrity_msgs::msg::dds_::Command_& cmd, const WriterId& writer, int endcap_id) {
  CommandSample c;
  c.writer = writer;
  c.format_version = cmd.format_version();
  c.seq = cmd.seq();
  c.kind = cmd.kind();
  c.endcap_mask = cmd.endcap_mask();
  c.start_host_time_ns = cmd.start_host_time_ns();
  c.issued_host_time_ns = cmd.issued_host_time_ns();
  if (endcap_id >= 0 && static_cast<std::size_t>(endcap_id) < cmd.estops_seen().size()) {
    c.estops_seen.life_id = cmd.lives_seen()[static_cast<std::size_t>(endcap_id)];
    c.estops_seen.count = cmd.estops_seen()[static_cast<std::size_t>(endcap_id)];
  }
  c.asked_host_time_ns = cmd.asked_host_time_ns();
  return c;
}

}  // namespace tensegrity::fw::comms
