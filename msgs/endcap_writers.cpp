// SPDX-License-Identifier: Apache-2.0
#include "msgs/endcap_writers.hpp"

#include <cstdio>

#include "msgs/dds.hpp"
#include "msgs/security.hpp"

namespace tensegrity::msgs {

namespace dds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

namespace {
constexpr std::string_view kPrefix = "endcap_";
}  // namespace

std::string endcap_partition(int endcap_id) {
  if (endcap_id < 0 || endcap_id >= kMaxEndcaps) {
    throw DdsError("end cap id " + std::to_string(endcap_id) + ": expected 0.." + std::to_string(kMaxEndcaps - 1));
  }
  char name[16];
  std::snprintf(name, sizeof name, "endcap_%02d", endcap_id);
  return name;
}

int endcap_of_partition(std::string_view partition) {
  if (partition.size() != kPrefix.size() + 2 || partition.substr(0, kPrefix.size()) != kPrefix) return -1;
  const char tens = partition[kPrefix.size()], ones = partition[kPrefix.size() + 1];
  if (tens < '0' || tens > '9' || ones < '0' || ones > '9') return -1;
  const int id = (tens - '0') * 10 + (ones - '0');
  return id < kMaxEndcaps ? id : -1;
}

dds::PublisherQos endcap_publisher_qos(int endcap_id) {
  dds::PublisherQos qos = dds::PUBLISHER_QOS_DEFAULT;
  qos.partition().push_back(endcap_partition(endcap_id).c_str());
  return qos;
}

dds::SubscriberQos endcap_reports_qos() {
  dds::SubscriberQos qos = dds::SUBSCRIBER_QOS_DEFAULT;
  qos.partition().push_back(kEveryEndcapPartition);
  return qos;
}

void EndcapWriters::on_publisher_discovery(dds::DomainParticipant*, rtps::WriterDiscoveryInfo&& info) {
  const rtps::GUID_t guid = info.info.guid();
  std::lock_guard lock(mutex_);
  if (info.status == rtps::WriterDiscoveryInfo::REMOVED_WRITER) {
    endcap_of_writer_.erase(guid);
    return;
  }
  const auto& partitions = info.info.m_qos.m_partition;
  int endcap = -1;
  if (partitions.size() == 1) endcap = endcap_of_partition(partitions.begin()->name());
  const auto [it, first] = endcap_of_writer_.try_emplace(guid, endcap);
  if (first || it->second == endcap) return;
  // Partition is a mutable QoS, and Fast DDS 2.9.1 checks a remote writer's
  // partitions against its permissions when it matches the writer, not when a QoS
  // update moves it (SecureDds.AnEndcapIdentityCannotMoveItsWritersIntoAnotherPartition
  // found an end cap's writer moved into another's partition accepted). An end cap's
  // writers never move, so one that does speaks for no end cap from then on.
  if (it->second >= 0) {
    std::fprintf(stderr, "REFUSED from now on: a writer of end cap %d moved to partition %s\n", it->second,
                 partitions.size() == 1 ? partitions.begin()->name() : "(several or none)");
  }
  it->second = -1;
}

int EndcapWriters::endcap_of(const dds::SampleInfo& info) const {
  std::lock_guard lock(mutex_);
  const auto it = endcap_of_writer_.find(info.sample_identity.writer_guid());
  return it == endcap_of_writer_.end() ? -1 : it->second;
}

std::uint32_t EndcapWriters::endcaps_of_participants(const std::function<bool(const rtps::GuidPrefix_t&)>& pick) const {
  std::lock_guard lock(mutex_);
  std::uint32_t mask = 0;
  for (const auto& [guid, endcap] : endcap_of_writer_) {
    if (endcap >= 0 && pick(guid.guidPrefix)) mask |= 1U << endcap;
  }
  return mask;
}

}  // namespace tensegrity::msgs
