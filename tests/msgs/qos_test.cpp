// SPDX-License-Identifier: Apache-2.0
// Every writer/reader pair the project creates, with its real profile, between two
// real participants on loopback: each writer must match its reader and no
// incompatible-QoS callback may fire. Also: the profiles turn data sharing off
// and the participant uses UDP only (interop with emulated/ARM processes).
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <map>
#include <thread>

#include "msgs/dds.hpp"
#include "tensegrity_msgs/msg/CommandAckPubSubTypes.h"
#include "tensegrity_msgs/msg/CommandPubSubTypes.h"
#include "tensegrity_msgs/msg/HeartbeatPubSubTypes.h"
#include "tensegrity_msgs/msg/PolicyAckPubSubTypes.h"
#include "tensegrity_msgs/msg/PolicyTablePubSubTypes.h"
#include "tensegrity_msgs/msg/TelemetryPubSubTypes.h"
#include "tensegrity_msgs/msg/TimeSyncPubSubTypes.h"

namespace tensegrity::msgs {
namespace {

namespace dds = eprosima::fastdds::dds;
namespace m = tensegrity_msgs::msg::dds_;

constexpr int kDomain = 171;  // unique per DDS test: ctest runs tests in parallel

dds::TypeSupport type_for(const TopicSpec& spec) {
  const std::string t = spec.type;
  if (t == kPolicyTableTopic.type) return dds::TypeSupport(new m::PolicyTable_PubSubType());
  if (t == kPolicyAckTopic.type) return dds::TypeSupport(new m::PolicyAck_PubSubType());
  if (t == kCommandTopic.type) return dds::TypeSupport(new m::Command_PubSubType());
  if (t == kCommandAckTopic.type) return dds::TypeSupport(new m::CommandAck_PubSubType());
  if (t == kTelemetryTopic.type) return dds::TypeSupport(new m::Telemetry_PubSubType());
  if (t == kHostHeartbeatTopic.type) return dds::TypeSupport(new m::Heartbeat_PubSubType());
  if (t == kTimeSyncRequestTopic.type) return dds::TypeSupport(new m::TimeSyncRequest_PubSubType());
  return dds::TypeSupport(new m::TimeSyncReply_PubSubType());
}

struct Counts : dds::DataWriterListener, dds::DataReaderListener {
  std::atomic<int> writer_matched{0};
  std::atomic<int> reader_matched{0};
  std::atomic<int> incompatible{0};
  void on_publication_matched(dds::DataWriter*, const dds::PublicationMatchedStatus& s) override {
    writer_matched = s.current_count;
  }
  void on_subscription_matched(dds::DataReader*, const dds::SubscriptionMatchedStatus& s) override {
    reader_matched = s.current_count;
  }
  void on_offered_incompatible_qos(dds::DataWriter*, const dds::OfferedIncompatibleQosStatus&) override {
    ++incompatible;
  }
  void on_requested_incompatible_qos(dds::DataReader*, const dds::RequestedIncompatibleQosStatus&) override {
    ++incompatible;
  }
};

TEST(Qos, EveryWriterMatchesItsReaderWithoutIncompatibility) {
  dds::DomainParticipant* a = create_participant(kDomain, "qos_test_writer");
  dds::DomainParticipant* b = create_participant(kDomain, "qos_test_reader");
  dds::Publisher* pub = a->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  dds::Subscriber* sub = b->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  std::map<std::string, std::unique_ptr<Counts>> counts;
  for (const TopicSpec& spec : kAllTopics) {
    auto c = std::make_unique<Counts>();
    dds::Topic* ta = create_topic(*a, spec, type_for(spec));
    dds::Topic* tb = create_topic(*b, spec, type_for(spec));
    dds::DataWriter* w = pub->create_datawriter_with_profile(ta, spec.profile, c.get());
    dds::DataReader* r = sub->create_datareader_with_profile(tb, spec.profile, c.get());
    ASSERT_NE(w, nullptr) << spec.name;
    ASSERT_NE(r, nullptr) << spec.name;
    // Data sharing is on by default for bounded types: the profiles must turn it off.
    EXPECT_EQ(w->get_qos().data_sharing().kind(), dds::OFF) << spec.name;
    EXPECT_EQ(r->get_qos().data_sharing().kind(), dds::OFF) << spec.name;
    counts[spec.name] = std::move(c);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  auto all_matched = [&] {
    for (const auto& [name, c] : counts) {
      if (c->writer_matched < 1 || c->reader_matched < 1) return false;
    }
    return true;
  };
  while (!all_matched() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // let a late incompatibility report arrive
  for (const auto& [name, c] : counts) {
    EXPECT_EQ(c->writer_matched.load(), 1) << name;
    EXPECT_EQ(c->reader_matched.load(), 1) << name;
    EXPECT_EQ(c->incompatible.load(), 0) << name;
  }
  delete_participant(a);
  delete_participant(b);
}

TEST(Qos, DurableAndStreamProfilesAreWhatTheDesignSays) {
  load_qos_profiles();
  auto* factory = dds::DomainParticipantFactory::get_instance();
  dds::DomainParticipant* p = create_participant(kDomain, "qos_test_profiles");
  dds::Publisher* pub = p->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  dds::DataWriterQos q;
  ASSERT_EQ(pub->get_datawriter_qos_from_profile(kProfileDurable, q), ReturnCode_t::RETCODE_OK);
  EXPECT_EQ(q.reliability().kind, dds::RELIABLE_RELIABILITY_QOS);
  EXPECT_EQ(q.durability().kind, dds::TRANSIENT_LOCAL_DURABILITY_QOS);
  // A lost table or ack is repaired within 0.1 s, not Fast DDS's default 3 s.
  EXPECT_EQ(q.reliable_writer_qos().times.heartbeatPeriod, eprosima::fastrtps::Duration_t(0, 100'000'000));
  ASSERT_EQ(pub->get_datawriter_qos_from_profile(kProfileStream, q), ReturnCode_t::RETCODE_OK);
  EXPECT_EQ(q.reliability().kind, dds::BEST_EFFORT_RELIABILITY_QOS);
  EXPECT_EQ(q.durability().kind, dds::VOLATILE_DURABILITY_QOS);
  // UDP only: no built-in (SHM) transport, one user transport.
  const dds::DomainParticipantQos pq = p->get_qos();
  EXPECT_FALSE(pq.transport().use_builtin_transports);
  ASSERT_EQ(pq.transport().user_transports.size(), 1U);
  (void)factory;
  delete_participant(p);
}

}  // namespace
}  // namespace tensegrity::msgs
