// SPDX-License-Identifier: Apache-2.0
// End cap partition names, both ways, and a writer that changes partition. The
// binding of samples to their writers' partitions is tested over DDS too
// (tests/ground/security_dds_test.cpp, the view's test).
#include "msgs/endcap_writers.hpp"

#include <gtest/gtest.h>

#include "msgs/dds.hpp"

namespace tensegrity::msgs {
namespace {

TEST(EndcapPartitions, NamesRoundTrip) {
  for (int id = 0; id < 12; ++id) EXPECT_EQ(endcap_of_partition(endcap_partition(id)), id);
  EXPECT_EQ(endcap_partition(3), "endcap_03");
  EXPECT_THROW(endcap_partition(12), DdsError);
  EXPECT_THROW(endcap_partition(-1), DdsError);
}

TEST(EndcapPartitions, AnyOtherNameIsNoEndcap) {
  for (const char* name : {"", "endcap_*", "endcap_12", "endcap_3", "endcap_003", "endcap_-1", "Endcap_03", "endcap_0a",
                           "xendcap_03", "endcap_03 "}) {
    EXPECT_EQ(endcap_of_partition(name), -1) << name;
  }
}

TEST(EndcapPartitions, QosCarriesThem) {
  const auto pub = endcap_publisher_qos(7);
  ASSERT_EQ(pub.partition().size(), 1U);
  EXPECT_STREQ(pub.partition().begin()->name(), "endcap_07");
  const auto sub = endcap_reports_qos();
  ASSERT_EQ(sub.partition().size(), 1U);
  EXPECT_STREQ(sub.partition().begin()->name(), kEveryEndcapPartition);
}

TEST(EndcapWriters, AnUnknownWriterVouchesForNobody) {
  const EndcapWriters writers;
  eprosima::fastdds::dds::SampleInfo info;
  EXPECT_EQ(writers.endcap_of(info), -1);
  EXPECT_FALSE(writers.vouches(info, 0));
  EXPECT_FALSE(writers.vouches(info, -1));
}

// A writer discovered in end cap 1's partition that later announces end cap 2's
// (a QoS update; docs/guide/security.md "A writer that moves") vouches for nobody again.
TEST(EndcapWriters, AWriterThatChangesPartitionVouchesForNobodyFromThenOn) {
  namespace rtps = eprosima::fastrtps::rtps;
  EndcapWriters writers;
  rtps::WriterProxyData data(4, 4);
  rtps::GUID_t guid;
  guid.guidPrefix.value[0] = 7;
  guid.entityId.value[3] = 3;
  data.guid(guid);
  auto announce = [&](const char* partition, rtps::WriterDiscoveryInfo::DISCOVERY_STATUS status) {
    data.m_qos.m_partition.clear();
    data.m_qos.m_partition.push_back(partition);
    rtps::WriterDiscoveryInfo info(data);
    info.status = status;
    writers.on_publisher_discovery(nullptr, std::move(info));
  };
  eprosima::fastdds::dds::SampleInfo sample;
  sample.sample_identity.writer_guid(guid);
  announce("endcap_01", rtps::WriterDiscoveryInfo::DISCOVERED_WRITER);
  EXPECT_TRUE(writers.vouches(sample, 1));
  announce("endcap_01", rtps::WriterDiscoveryInfo::CHANGED_QOS_WRITER);  // same partition: still end cap 1
  EXPECT_TRUE(writers.vouches(sample, 1));
  announce("endcap_02", rtps::WriterDiscoveryInfo::CHANGED_QOS_WRITER);
  EXPECT_FALSE(writers.vouches(sample, 2));
  EXPECT_FALSE(writers.vouches(sample, 1));
  announce("endcap_01", rtps::WriterDiscoveryInfo::CHANGED_QOS_WRITER);  // moving back does not help
  EXPECT_FALSE(writers.vouches(sample, 1));
  announce("endcap_01", rtps::WriterDiscoveryInfo::REMOVED_WRITER);
  EXPECT_EQ(writers.endcap_of(sample), -1);
}

}  // namespace
}  // namespace tensegrity::msgs
