// SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>

#include "msgs/dds.hpp"

namespace tensegrity::msgs {
namespace {

TEST(Domain, DefaultAndOverride) {
  ::unsetenv("TENSEGRITY_DOMAIN");
  EXPECT_EQ(domain_id(), kDefaultDomain);
  ::setenv("TENSEGRITY_DOMAIN", "7", 1);
  EXPECT_EQ(domain_id(), 7);
  ::unsetenv("TENSEGRITY_DOMAIN");
}

TEST(Domain, BadValuesAreClearErrors) {
  for (const char* bad : {"-1", "233", "4x", "x", " 5"}) {
    try {
      parse_domain_id(bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const DdsError& e) {
      EXPECT_NE(std::strstr(e.what(), "TENSEGRITY_DOMAIN"), nullptr) << e.what();
    }
  }
  EXPECT_EQ(parse_domain_id("232"), 232);
}

TEST(Topics, FollowRos2Conventions) {
  for (const TopicSpec& t : kAllTopics) {
    EXPECT_EQ(std::string(t.name).rfind("rt/tensegrity/", 0), 0U) << t.name;
    const std::string type = t.type;
    EXPECT_EQ(type.rfind("tensegrity_msgs::msg::dds_::", 0), 0U) << type;
    EXPECT_EQ(type.back(), '_') << type;
  }
}

}  // namespace
}  // namespace tensegrity::msgs
