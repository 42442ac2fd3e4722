// SPDX-License-Identifier: Apache-2.0
// What every DDS participant of the project agrees on: the message-format version,
// the domain id, the topic names with their QoS profile, and how a participant is
// made (UDP only, profiles from msgs/qos_profiles.xml). See docs/design/dds.md.
#pragma once

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <array>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include "msgs/format_version.hpp"  // kFormatVersion, every message's first field

namespace tensegrity::msgs {

class DdsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr int kDefaultDomain = 42;
// TENSEGRITY_DOMAIN if set (0..232, the range whose RTPS ports fit in 16 bits),
// else kDefaultDomain. Throws DdsError naming the variable on a bad value.
int domain_id();
int parse_domain_id(std::string_view text);

// QoS profile names in msgs/qos_profiles.xml.
inline constexpr const char* kProfileDurable = "durable_events";
inline constexpr const char* kProfileStream = "stream";
inline constexpr const char* kProfileTimeSync = "time_sync";
// The end cap's command reader: durable_events but VOLATILE, so a fresh end cap is
// never handed commands a writer kept from before it matched (docs/design/dds.md).
inline constexpr const char* kProfileFreshCommands = "fresh_commands";
inline constexpr const char* kParticipantProfile = "tensegrity_participant";

// Which side writes a topic: the DDS Security permissions are made from this column
// (msgs/security.hpp), so only the ground station's identity may give orders.
enum class Writer : std::uint8_t { ground, endcap };

struct TopicSpec {
  const char* name;     // ROS 2 style: "rt/" + ROS topic name
  const char* type;     // registered type name (ROS 2: pkg::msg::dds_::Type_)
  const char* profile;  // writer and reader profile of this topic
  Writer writer;
};

inline constexpr TopicSpec kPolicyTableTopic{"rt/tensegrity/policy_table", "tensegrity_msgs::msg::dds_::PolicyTable_",
                                             kProfileDurable, Writer::ground};
inline constexpr TopicSpec kPolicyAckTopic{"rt/tensegrity/policy_ack", "tensegrity_msgs::msg::dds_::PolicyAck_",
                                           kProfileDurable, Writer::endcap};
inline constexpr TopicSpec kCommandTopic{"rt/tensegrity/command", "tensegrity_msgs::msg::dds_::Command_",
                                         kProfileDurable, Writer::ground};
inline constexpr TopicSpec kCommandAckTopic{"rt/tensegrity/command_ack", "tensegrity_msgs::msg::dds_::CommandAck_",
                                            kProfileDurable, Writer::endcap};
inline constexpr TopicSpec kTelemetryTopic{"rt/tensegrity/telemetry", "tensegrity_msgs::msg::dds_::Telemetry_",
                                           kProfileStream, Writer::endcap};
inline constexpr TopicSpec kHostHeartbeatTopic{"rt/tensegrity/host_heartbeat", "tensegrity_msgs::msg::dds_::Heartbeat_",
                                               kProfileStream, Writer::ground};
inline constexpr TopicSpec kEndcapHeartbeatTopic{
    "rt/tensegrity/endcap_heartbeat", "tensegrity_msgs::msg::dds_::Heartbeat_", kProfileStream, Writer::endcap};
inline constexpr TopicSpec kTimeSyncRequestTopic{"rt/tensegrity/time_sync_request",
                                                 "tensegrity_msgs::msg::dds_::TimeSyncRequest_", kProfileTimeSync,
                                                 Writer::endcap};
inline constexpr TopicSpec kTimeSyncReplyTopic{
    "rt/tensegrity/time_sync_reply", "tensegrity_msgs::msg::dds_::TimeSyncReply_", kProfileTimeSync, Writer::ground};

inline constexpr std::array<TopicSpec, 9> kAllTopics{kPolicyTableTopic,     kPolicyAckTopic,       kCommandTopic,
                                                     kCommandAckTopic,      kTelemetryTopic,       kHostHeartbeatTopic,
                                                     kEndcapHeartbeatTopic, kTimeSyncRequestTopic, kTimeSyncReplyTopic};

// Loads the QoS profiles once per process: TENSEGRITY_QOS_FILE if set, else the
// copy compiled in. Throws DdsError when Fast DDS rejects the XML.
void load_qos_profiles();

// A participant on `domain` with the UDP-only profile; throws DdsError on failure.
// With `enclave_dir` (a keystore's enclave folder, msgs/security.hpp) the DDS
// Security plugins authenticate it and enforce the enclave's permissions; empty:
// an unsecured participant, which a secured one never talks to.
// Delete with delete_participant (deletes its entities first). With `faults`, its
// transport drops datagrams while a fault's flag is set (fault injection:
// msgs/link_cut_transport.hpp); the flags must outlive the participant.
// `listener` (e.g. msgs::EndcapWriters) hears discovery from the first datagram on
// (no status callbacks: the readers' own listeners keep those); it must outlive it.
struct LinkFaults {
  const std::atomic<bool>* cut = nullptr;   // while true: nothing in or out (a lost link)
  const std::atomic<bool>* mute = nullptr;  // while true: nothing out; it still hears
};
eprosima::fastdds::dds::DomainParticipant* create_participant(
    int domain, const std::string& name, const LinkFaults& faults = {}, const std::filesystem::path& enclave_dir = {},
    eprosima::fastdds::dds::DomainParticipantListener* listener = nullptr);
void delete_participant(eprosima::fastdds::dds::DomainParticipant* participant) noexcept;

// Registers `type` (once per participant) and creates the topic of `spec` (or
// returns the participant's existing one).
eprosima::fastdds::dds::Topic* create_topic(eprosima::fastdds::dds::DomainParticipant& participant,
                                            const TopicSpec& spec, eprosima::fastdds::dds::TypeSupport type);

// The writer / reader of `spec`'s topic with its QoS profile; both ends of the link
// (the end cap's node and the ground station) create theirs through these.
// Throw DdsError naming the topic.
eprosima::fastdds::dds::DataWriter* create_writer(eprosima::fastdds::dds::DomainParticipant& participant,
                                                  eprosima::fastdds::dds::Publisher& publisher, const TopicSpec& spec,
                                                  eprosima::fastdds::dds::TypeSupport type,
                                                  eprosima::fastdds::dds::DataWriterListener* listener = nullptr);
eprosima::fastdds::dds::DataReader* create_reader(eprosima::fastdds::dds::DomainParticipant& participant,
                                                  eprosima::fastdds::dds::Subscriber& subscriber, const TopicSpec& spec,
                                                  eprosima::fastdds::dds::TypeSupport type,
                                                  eprosima::fastdds::dds::DataReaderListener* listener);

}  // namespace tensegrity::msgs
