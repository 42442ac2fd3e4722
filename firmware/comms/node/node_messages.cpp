// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/node/node_messages.hpp"

#include <array>

#include "msgs/format_version.hpp"

namespace tensegrity::fw::comms {

namespace m = tensegrity_msgs::msg::dds_;

m::PolicyAck_ policy_ack_message(const NodeFacts& facts, const PolicyTableMsg& msg, PolicyReason reason,
                                 const std::string& text) {
  m::PolicyAck_ ack;
  ack.format_version(msgs::kFormatVersion);
  ack.endcap_id(static_cast<std::int16_t>(facts.endcap_id));
  ack.upload_sequence(msg.upload_sequence());
  ack.accepted(is_accepted(reason));
  ack.reason(static_cast<std::uint8_t>(reason));
  ack.reason_text(text.substr(0, 128));
  ack.active_policy_id(facts.active.policy_id);
  ack.active_policy_version(facts.active.policy_version);
  ack.active_checksum(facts.active.checksum);
  return ack;
}

m::CommandAck_ command_ack_message(const NodeFacts& facts, std::uint32_t seq, CommandReason reason) {
  m::CommandAck_ ack;
  ack.format_version(msgs::kFormatVersion);
  ack.endcap_id(static_cast<std::int16_t>(facts.endcap_id));
  ack.seq(seq);
  ack.accepted(reason == CommandReason::accepted);
  ack.reason(static_cast<std::uint8_t>(reason));
  ack.reason_text(describe(reason));
  ack.life_id(facts.life_id);
  ack.estops_received(facts.estops);
  return ack;
}

m::Telemetry_ telemetry_message(const NodeFacts& facts, std::uint32_t seq, const app::Telemetry& t,
                                std::int64_t local_ns) {
  m::Telemetry_ msg;
  msg.format_version(msgs::kFormatVersion);
  msg.endcap_id(static_cast<std::int16_t>(facts.endcap_id));
  msg.seq(seq);
  msg.host_time_ns(facts.sync.synced ? local_ns + facts.sync.offset_ns : 0);
  msg.loop_time_ns(t.time_ns);
  msg.cycle(t.cycle);
  msg.mode(static_cast<std::uint8_t>(t.mode));
  msg.fault(static_cast<std::uint8_t>(t.fault));
  msg.motor_count(t.motor_count);
  msg.subinterval(t.subinterval);
  msg.cutoff_mask(t.cutoff_mask);
  msg.drives_enabled(t.drives_enabled);
  std::array<double, 4> commanded{}, measured{}, tension{};
  for (std::size_t i = 0; i < 4 && i < core::kMaxMotorsPerEndcap; ++i) {
    commanded[i] = t.commanded_rest_length_m[i];
    measured[i] = t.measured_rest_length_m[i];
    tension[i] = t.tension_n[i];
  }
  msg.commanded_rest_length_m(commanded);
  msg.measured_rest_length_m(measured);
  msg.tension_n(tension);
  msg.loop_overruns(t.overruns);
  msg.active_policy_id(facts.active.policy_id);
  msg.active_policy_version(facts.active.policy_version);
  return msg;
}

m::Heartbeat_ heartbeat_message(const NodeFacts& facts, std::uint32_t seq, std::int64_t now_ns,
                                const app::Telemetry& t) {
  m::Heartbeat_ hb;
  hb.format_version(msgs::kFormatVersion);
  hb.source(static_cast<std::int16_t>(facts.endcap_id));
  hb.seq(seq);
  hb.time_ns(now_ns);
  hb.mode(static_cast<std::uint8_t>(t.mode));
  hb.fault(static_cast<std::uint8_t>(t.fault));
  hb.active_policy_id(facts.active.policy_id);
  hb.active_policy_version(facts.active.policy_version);
  hb.clock_synced(facts.sync.synced);
  hb.clock_offset_ns(facts.sync.offset_ns);
  hb.clock_round_trip_ns(facts.sync.round_trip_ns);
  hb.host_lost(facts.host_lost);
  hb.host_loss_action(static_cast<std::uint8_t>(facts.host_loss));
  hb.loop_overruns(t.overruns);
  hb.life_id(facts.life_id);
  hb.estops_received(facts.estops);
  return hb;
}

}  // namespace tensegrity::fw::comms
