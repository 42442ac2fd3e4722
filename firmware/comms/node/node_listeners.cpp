// SPDX-License-Identifier: Apache-2.0
// The node's DDS participant and what runs on Fast DDS's receive thread: commands
// (CommandHandler decides; an emergency stop is latched there, never waiting behind
// a table being stored) and time-sync replies (SharedTimeSync). Every addressed
// command is acked, whatever the answer, on both participants during a rejoin's
// overlap.
#include <cstring>
#include <functional>
#include <string>

#include "firmware/comms/logic/command_wire.hpp"
#include "firmware/comms/node/endcap_node.hpp"
#include "firmware/comms/node/node_dds.hpp"
#include "firmware/comms/node/node_messages.hpp"
#include "msgs/endcap_writers.hpp"
#include "tensegrity_msgs/msg/CommandAckPubSubTypes.h"
#include "tensegrity_msgs/msg/CommandPubSubTypes.h"
#include "tensegrity_msgs/msg/HeartbeatPubSubTypes.h"
#include "tensegrity_msgs/msg/PolicyAckPubSubTypes.h"
#include "tensegrity_msgs/msg/PolicyTablePubSubTypes.h"
#include "tensegrity_msgs/msg/TelemetryPubSubTypes.h"
#include "tensegrity_msgs/msg/TimeSyncPubSubTypes.h"

namespace tensegrity::fw::comms {

namespace m = tensegrity_msgs::msg::dds_;

namespace {

WriterId writer_of(const dds::SampleInfo& info) {
  WriterId w;
  const auto& guid = info.sample_identity.writer_guid();
  static_assert(sizeof(guid.guidPrefix.value) + sizeof(guid.entityId.value) == sizeof(WriterId));
  std::memcpy(w.data(), guid.guidPrefix.value, sizeof(guid.guidPrefix.value));
  std::memcpy(w.data() + sizeof(guid.guidPrefix.value), guid.entityId.value, sizeof(guid.entityId.value));
  return w;
}

}  // namespace

std::unique_ptr<NodeParticipant> EndcapNode::make_participant() {
  auto d = std::make_unique<NodeParticipant>();
  const msgs::LinkFaults faults{config_.link_cut, config_.mute_requests != nullptr ? &d->muted : nullptr};
  d->participant = msgs::create_participant(config_.domain, "endcap" + std::to_string(config_.endcap_id), faults,
                                            config_.enclave_dir);
  // Reports go out in this end cap's own partition, the only one its identity may
  // write in (msgs/endcap_writers.hpp); orders come in the default one.
  d->publisher = d->participant->create_publisher(msgs::endcap_publisher_qos(config_.endcap_id));
  d->subscriber = d->participant->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (d->publisher == nullptr || d->subscriber == nullptr) throw msgs::DdsError("cannot create publisher/subscriber");
  d->policy_ack = d->writer(msgs::kPolicyAckTopic, dds::TypeSupport(new m::PolicyAck_PubSubType()));
  d->command_ack = d->writer(msgs::kCommandAckTopic, dds::TypeSupport(new m::CommandAck_PubSubType()));
  d->telemetry = d->writer(msgs::kTelemetryTopic, dds::TypeSupport(new m::Telemetry_PubSubType()));
  d->heartbeat = d->writer(msgs::kEndcapHeartbeatTopic, dds::TypeSupport(new m::Heartbeat_PubSubType()));
  d->sync_request = d->writer(msgs::kTimeSyncRequestTopic, dds::TypeSupport(new m::TimeSyncRequest_PubSubType()));
  NodeParticipant* raw = d.get();  // the listeners reach their own entities, never through participants_
  auto listener = [this, raw](std::function<void()> fn, const char* topic) {
    raw->listeners.push_back(std::make_unique<CallbackListener>(std::move(fn), topic, config_.endcap_id, config_.log));
    return raw->listeners.back().get();
  };
  // Readers last: a callback may fire as soon as a reader exists, and it may use
  // the writers. The two that work in the receive thread reach their reader
  // through `raw` under its mutex.
  dds::DataReader* sync_reply =
      d->reader(msgs::kTimeSyncReplyTopic, dds::TypeSupport(new m::TimeSyncReply_PubSubType()),
                listener([this, raw] { on_time_sync_reply(*raw); }, msgs::kTimeSyncReplyTopic.name));
  const msgs::TopicSpec fresh_commands{msgs::kCommandTopic.name, msgs::kCommandTopic.type, msgs::kProfileFreshCommands,
                                       msgs::kCommandTopic.writer};
  dds::DataReader* command = d->reader(fresh_commands, dds::TypeSupport(new m::Command_PubSubType()),
                                       listener([this, raw] { on_commands(*raw); }, msgs::kCommandTopic.name));
  {
    std::lock_guard lock(d->callback_mutex);
    d->sync_reply = sync_reply;
    d->command = command;
  }
  // These two only wake the node thread, which reads them once this one is adopted.
  d->policy = d->reader(msgs::kPolicyTableTopic, dds::TypeSupport(new m::PolicyTable_PubSubType()),
                        listener([this] { wake(); }, msgs::kPolicyTableTopic.name));
  d->host_heartbeat = d->reader(msgs::kHostHeartbeatTopic, dds::TypeSupport(new m::Heartbeat_PubSubType()),
                                listener([this] { wake(); }, msgs::kHostHeartbeatTopic.name));
  return d;
}

void EndcapNode::on_commands(NodeParticipant& d) {
  std::lock_guard guard(d.callback_mutex);
  if (d.closed || d.command == nullptr) return;   // stopping, or still starting (taken next time)
  std::lock_guard serial(participants_->serial);  // the other participant's listener, after a rejoin
  m::Command_ cmd;
  dds::SampleInfo info;
  while (d.command->take_next_sample(&cmd, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    const CommandSample c = to_sample(cmd, writer_of(info), config_.endcap_id);
    const std::optional<CommandReason> reason = commands_.handle(c, sync_.view(), clock_.now_ns());
    if (!reason) continue;  // addressed to other end caps
    NodeFacts facts{};
    facts.endcap_id = config_.endcap_id;
    facts.life_id = commands_.life_id();
    facts.estops = commands_.estops();
    m::CommandAck_ ack = command_ack_message(facts, c.seq, *reason);
    d.command_ack->write(&ack);
    // During a rejoin's overlap the host may hear only the other participant (a muted
    // old one, or a new one not yet matched); the station takes the first ack of a sequence.
    if (d.peer != nullptr) d.peer->command_ack->write(&ack);
  }
}

void EndcapNode::on_time_sync_reply(NodeParticipant& d) {
  std::lock_guard guard(d.callback_mutex);
  if (d.closed || d.sync_reply == nullptr) return;  // stopping, or still starting (taken next time)
  if (d.retiring) return;                           // its replies reach the new participant too: counted there once
  m::TimeSyncReply_ reply;
  dds::SampleInfo info;
  while (d.sync_reply->take_next_sample(&reply, &info) == ReturnCode_t::RETCODE_OK) {
    const std::int64_t t4 = clock_.now_ns();  // stamped before anything else
    if (!info.valid_data || reply.endcap_id() != config_.endcap_id) continue;
    if (reply.format_version() != msgs::kFormatVersion) continue;
    sync_.on_reply(reply.nonce(), reply.t2_ns(), reply.t3_ns(), t4);
  }
}

}  // namespace tensegrity::fw::comms
