// SPDX-License-Identifier: Apache-2.0
// Which end cap a report comes from, judged by the writer that sent it rather than
// by the id the sample claims. Each end cap publishes its reports (acks, telemetry,
// heartbeats, time-sync requests) in its own partition, "endcap_NN"; the DDS
// Security permissions let end cap NN's identity write there and nowhere else
// (msgs/security.cpp), and Fast DDS checks a remote writer's partitions against its
// permissions before it matches it. A reader of reports listens to every end cap's
// partition ("endcap_*") and remembers, for each writer it discovers, the end cap
// its partition names; a sample whose id is not its writer's is refused. A writer
// whose partition changes after discovery is refused from then on (Fast DDS checks
// permissions when it matches a writer, not when its QoS changes). So one end cap's
// identity cannot speak for another. docs/guide/security.md.
#pragma once

#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/qos/PublisherQos.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/qos/SubscriberQos.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <string_view>

namespace tensegrity::msgs {

// "endcap_03". Throws DdsError for an id outside 0..11.
std::string endcap_partition(int endcap_id);
// What a reader of every end cap's reports subscribes to (a DDS partition pattern).
inline constexpr const char* kEveryEndcapPartition = "endcap_*";
// The id of a partition named exactly "endcap_NN" (NN in 00..11); -1 for any other.
int endcap_of_partition(std::string_view partition);

// The publisher QoS an end cap writes its reports with, and the subscriber QoS the
// ground station, the view and listeners read them with.
eprosima::fastdds::dds::PublisherQos endcap_publisher_qos(int endcap_id);
eprosima::fastdds::dds::SubscriberQos endcap_reports_qos();

// A participant listener (give it to create_participant, so that no discovery is
// missed) that keeps each discovered writer's end cap. Thread-safe: discovery and
// the readers' callbacks run in different Fast DDS threads.
class EndcapWriters final : public eprosima::fastdds::dds::DomainParticipantListener {
 public:
  void on_publisher_discovery(eprosima::fastdds::dds::DomainParticipant* participant,
                              eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override;
  // The end cap whose partition (and only that one) the sample's writer publishes
  // in; -1 when it publishes in none, in several, or was never discovered.
  int endcap_of(const eprosima::fastdds::dds::SampleInfo& info) const;
  bool vouches(const eprosima::fastdds::dds::SampleInfo& info, int claimed_endcap) const {
    return claimed_endcap >= 0 && endcap_of(info) == claimed_endcap;
  }
  // The end caps (bit N for end cap N) with a writer from a participant for which
  // `pick` is true: which end caps a participant-wide fact (a matched reader) holds for.
  std::uint32_t endcaps_of_participants(
      const std::function<bool(const eprosima::fastrtps::rtps::GuidPrefix_t&)>& pick) const;

 private:
  mutable std::mutex mutex_;
  std::map<eprosima::fastrtps::rtps::GUID_t, int> endcap_of_writer_;
};

}  // namespace tensegrity::msgs
