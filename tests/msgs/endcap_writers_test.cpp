// SPDX-License-Identifier: Apache-2.0
// End cap partition names, both ways. The binding of samples to their writers'
// partitions is tested over DDS (tests/ground/security_dds_test.cpp, the view's test).
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

}  // namespace
}  // namespace tensegrity::msgs
