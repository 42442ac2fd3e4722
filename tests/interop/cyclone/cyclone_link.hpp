// SPDX-License-Identifier: Apache-2.0
// The Cyclone DDS side of what msgs/dds.hpp and msgs/qos_profiles.xml define for
// Fast DDS: the same topic names, the same type names (idlc derives them from the
// same IDL modules), the same QoS per topic. Only the topics the host-side peer
// needs: telemetry and policy acks in, policy tables out.
#pragma once

#include <dds/dds.h>

#include <cstdint>
#include <stdexcept>
#include <string>

#include "tensegrity_msgs_cyclone/PolicyAck.h"
#include "tensegrity_msgs_cyclone/PolicyTable.h"
#include "tensegrity_msgs_cyclone/Telemetry.h"

namespace tensegrity::interop {

using PolicyTableC = tensegrity_msgs_msg_dds__PolicyTable_;
using PolicyAckC = tensegrity_msgs_msg_dds__PolicyAck_;
using TelemetryC = tensegrity_msgs_msg_dds__Telemetry_;

// msgs/qos_profiles.xml's profiles, in Cyclone's terms.
enum class Profile { durable_events, stream };

struct CycloneTopic {
  const char* name;                          // "rt/" + ROS topic name, as msgs::k*Topic
  const dds_topic_descriptor_t* descriptor;  // its m_typename is the DDS type name
  Profile profile;
};

inline const CycloneTopic kPolicyTableTopic{"rt/tensegrity/policy_table", &tensegrity_msgs_msg_dds__PolicyTable__desc,
                                            Profile::durable_events};
inline const CycloneTopic kPolicyAckTopic{"rt/tensegrity/policy_ack", &tensegrity_msgs_msg_dds__PolicyAck__desc,
                                          Profile::durable_events};
inline const CycloneTopic kTelemetryTopic{"rt/tensegrity/telemetry", &tensegrity_msgs_msg_dds__Telemetry__desc,
                                          Profile::stream};

// Where the end caps write what the peer reads, as msgs::kEveryEndcapPartition
// (checked by the test: the peer prints it).
inline constexpr const char* kEndcapReportsPartition = "endcap_*";

class CycloneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One Cyclone participant on `domain`; the configuration (interfaces, discovery)
// comes from CYCLONEDDS_URI as for any Cyclone program. Entities are deleted with it.
class CycloneParticipant {
 public:
  explicit CycloneParticipant(int domain);
  ~CycloneParticipant();
  CycloneParticipant(const CycloneParticipant&) = delete;
  CycloneParticipant& operator=(const CycloneParticipant&) = delete;

  dds_entity_t handle() const { return participant_; }
  // Throw CycloneError naming the topic and Cyclone's return code.
  dds_entity_t writer(const CycloneTopic& topic);
  dds_entity_t reader(const CycloneTopic& topic);

 private:
  dds_entity_t topic(const CycloneTopic& topic);
  dds_entity_t participant_ = 0;
};

// Readers the peer has matched with so far (publication matched, for writers).
std::uint32_t matched_readers(dds_entity_t writer);

}  // namespace tensegrity::interop
