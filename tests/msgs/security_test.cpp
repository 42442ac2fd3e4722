// SPDX-License-Identifier: Apache-2.0
// The permissions documents come from the topic table's writer column: the ground
// alone may give orders, an end cap only reports, a listener only reads.
#include "msgs/security.hpp"

#include <gtest/gtest.h>

#include <cstdlib>

namespace tensegrity::msgs {
namespace {

std::string publish_block(const std::string& xml) {
  const auto from = xml.find("<publish>"), to = xml.find("</publish>");
  return from == std::string::npos ? std::string() : xml.substr(from, to - from);
}
std::string subscribe_block(const std::string& xml) {
  const auto from = xml.find("<subscribe>"), to = xml.find("</subscribe>");
  return from == std::string::npos ? std::string() : xml.substr(from, to - from);
}
bool lists(const std::string& block, const TopicSpec& t) {
  return block.find(std::string("<topic>") + t.name + "</topic>") != std::string::npos;
}

TEST(Security, OnlyTheGroundMayPublishOrders) {
  for (const TopicSpec& t : {kPolicyTableTopic, kCommandTopic, kTimeSyncReplyTopic, kHostHeartbeatTopic}) {
    EXPECT_TRUE(may_publish(Role::ground, t)) << t.name;
    EXPECT_FALSE(may_publish(Role::endcap, t)) << t.name;
    EXPECT_FALSE(may_publish(Role::listener, t)) << t.name;
  }
  for (const TopicSpec& t :
       {kPolicyAckTopic, kCommandAckTopic, kTelemetryTopic, kEndcapHeartbeatTopic, kTimeSyncRequestTopic}) {
    EXPECT_FALSE(may_publish(Role::ground, t)) << t.name;
    EXPECT_TRUE(may_publish(Role::endcap, t)) << t.name;
    EXPECT_FALSE(may_subscribe(Role::endcap, t)) << t.name << ": an end cap reads no other end cap";
    EXPECT_TRUE(may_subscribe(Role::ground, t)) << t.name;
  }
}

TEST(Security, PermissionsDocumentsFollowTheTable) {
  const std::string ground = permissions_xml("/tensegrity/ground", "2026-01-01T00:00:00", "2036-01-01T00:00:00");
  const std::string endcap = permissions_xml("/tensegrity/endcap_03", "2026-01-01T00:00:00", "2036-01-01T00:00:00");
  for (const TopicSpec& t : kAllTopics) {
    EXPECT_EQ(lists(publish_block(ground), t), t.writer == Writer::ground) << t.name;
    EXPECT_EQ(lists(publish_block(endcap), t), t.writer == Writer::endcap) << t.name;
    EXPECT_EQ(lists(subscribe_block(endcap), t), t.writer == Writer::ground) << t.name;
  }
  EXPECT_NE(endcap.find("<subject_name>CN=/tensegrity/endcap_03</subject_name>"), std::string::npos);
  EXPECT_NE(endcap.find("<default>DENY</default>"), std::string::npos);
  const std::string listener = permissions_xml("/tensegrity/listener", "a", "b");
  for (const TopicSpec& t : kAllTopics) EXPECT_FALSE(lists(publish_block(listener), t)) << t.name;
  EXPECT_NE(permissions_xml("/tensegrity/endcap_03", "a", "b").find(permission_rules("/tensegrity/endcap_03")),
            std::string::npos);
  EXPECT_THROW(permissions_xml("/tensegrity/endcap_12", "a", "b"), DdsError);
  EXPECT_THROW(permissions_xml("/other/ground", "a", "b"), DdsError);
}

// End cap 3's identity writes its reports in its partition and nowhere else (so it
// cannot speak for end cap 5); orders travel in the default partition; the ground
// and the listener read every end cap's partition.
TEST(Security, PartitionsBindAnEndcapIdentityToItsId) {
  const std::string endcap = permission_rules("/tensegrity/endcap_03");
  EXPECT_NE(publish_block(endcap).find("<partitions><partition>endcap_03</partition></partitions>"), std::string::npos);
  EXPECT_EQ(publish_block(endcap).find("<partition/>"), std::string::npos) << "no default partition for reports";
  EXPECT_NE(subscribe_block(endcap).find("<partitions><partition/></partitions>"), std::string::npos);
  const std::string ground = permission_rules("/tensegrity/ground");
  EXPECT_NE(publish_block(ground).find("<partitions><partition/></partitions>"), std::string::npos);
  EXPECT_NE(subscribe_block(ground).find("<partitions><partition>endcap_*</partition></partitions>"),
            std::string::npos);
  const std::string listener = permission_rules("/tensegrity/listener");
  EXPECT_NE(subscribe_block(listener).find("<partition/><partition>endcap_*</partition>"), std::string::npos);
  EXPECT_NE(permission_rules("/tensegrity/endcap_05"), endcap);
}

TEST(Security, EnclaveIdentities) {
  EXPECT_EQ(identity_of("/tensegrity/ground").role, Role::ground);
  EXPECT_EQ(identity_of("/tensegrity/listener").role, Role::listener);
  const Identity e = identity_of("/tensegrity/endcap_11");
  EXPECT_EQ(e.role, Role::endcap);
  EXPECT_EQ(e.endcap_id, 11);
  EXPECT_THROW(identity_of("/tensegrity/endcap_3"), DdsError);
  EXPECT_THROW(identity_of(""), DdsError);
}

TEST(Security, GovernanceRefusesTheUnauthenticated) {
  const std::string g = governance_xml();
  EXPECT_NE(g.find("<allow_unauthenticated_participants>false<"), std::string::npos);
  EXPECT_NE(g.find("<enable_join_access_control>true<"), std::string::npos);
  EXPECT_NE(g.find("<data_protection_kind>ENCRYPT<"), std::string::npos);
}

TEST(Security, EnclaveNamesAndFolders) {
  EXPECT_EQ(enclave_name(Role::ground), "/tensegrity/ground");
  EXPECT_EQ(enclave_name(Role::endcap, 7), "/tensegrity/endcap_07");
  EXPECT_THROW(enclave_name(Role::endcap, 12), DdsError);
  EXPECT_THROW(enclave_name(Role::endcap, -1), DdsError);
  EXPECT_EQ(enclave_dir("/k", "/tensegrity/endcap_07"), std::filesystem::path("/k/enclaves/tensegrity/endcap_07"));
  EXPECT_EQ(all_enclaves().size(), 14U);
  const EnclaveFiles f = enclave_files("/e");
  EXPECT_EQ(f.certificate, std::filesystem::path("/e/cert.pem"));
  EXPECT_EQ(f.permissions, std::filesystem::path("/e/permissions.p7s"));
}

TEST(Security, DefaultKeystore) {
  ::setenv("TENSEGRITY_KEYSTORE", "/opt/ks", 1);
  EXPECT_EQ(default_keystore(), std::filesystem::path("/opt/ks"));
  ::unsetenv("TENSEGRITY_KEYSTORE");
  ::setenv("XDG_DATA_HOME", "/data", 1);
  EXPECT_EQ(default_keystore(), std::filesystem::path("/data/tensegrity/keystore"));
  ::unsetenv("XDG_DATA_HOME");
}

TEST(Security, CheckEnclaveNamesTheMissingFile) {
  try {
    check_enclave(enclave_files("/nonexistent/enclave"));
    FAIL() << "no error";
  } catch (const DdsError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/enclave/identity_ca.cert.pem"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tensegrity::msgs
