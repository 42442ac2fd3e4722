// SPDX-License-Identifier: Apache-2.0
// The messages the end cap's node sends, built from what its parts know (no DDS
// entities: plain generated types, so what goes on the wire is checked in tests).
#pragma once

#include <cstdint>
#include <string>

#include "firmware/app/host_link.hpp"
#include "firmware/comms/node/node_config.hpp"
#include "firmware/comms/wire/policy_wire.hpp"
#include "firmware/comms/wire/reasons.hpp"
#include "firmware/comms/node/shared_time_sync.hpp"
#include "firmware/comms/node/table_inbox.hpp"
#include "tensegrity_msgs/msg/CommandAck.h"
#include "tensegrity_msgs/msg/Heartbeat.h"
#include "tensegrity_msgs/msg/PolicyAck.h"
#include "tensegrity_msgs/msg/Telemetry.h"

namespace tensegrity::fw::comms {

// What every report says about this end cap at the moment it is built.
struct NodeFacts {
  int endcap_id = 0;
  ActivePolicy active;
  SyncView sync;
  bool host_lost = false;
  HostLossAction host_loss = HostLossAction::stop;
  std::uint32_t life_id = 0;
  std::uint32_t estops = 0;
};

tensegrity_msgs::msg::dds_::PolicyAck_ policy_ack_message(const NodeFacts& facts, const PolicyTableMsg& msg,
                                                          PolicyReason reason, const std::string& text);
tensegrity_msgs::msg::dds_::CommandAck_ command_ack_message(const NodeFacts& facts, std::uint32_t seq,
                                                            CommandReason reason);
// `local_ns`: the node clock when the loop published `t`; host time only once synced.
tensegrity_msgs::msg::dds_::Telemetry_ telemetry_message(const NodeFacts& facts, std::uint32_t seq,
                                                         const app::Telemetry& t, std::int64_t local_ns);
tensegrity_msgs::msg::dds_::Heartbeat_ heartbeat_message(const NodeFacts& facts, std::uint32_t seq, std::int64_t now_ns,
                                                         const app::Telemetry& t);

}  // namespace tensegrity::fw::comms
