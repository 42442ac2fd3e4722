// SPDX-License-Identifier: Apache-2.0
// Strings an end cap writes (its policy id, an ack's reason text) are its bytes,
// not necessarily UTF-8. What the ground prints as JSON from them must still be
// printed: JSON cannot hold such bytes, and nlohmann throws rather than write them,
// which took `tensegrity status --json` and the operator console's reply down.
#include <gtest/gtest.h>

#include <array>
#include <string>

#include "ground/operator_protocol.hpp"
#include "ground/status.hpp"

namespace tensegrity::ground {
namespace {

const std::string kNotUtf8 = "policy-\xff\xfe";
const std::string kReplaced = "policy-\xef\xbf\xbd\xef\xbf\xbd";  // each bad byte as U+FFFD

TEST(WireText, StatusJsonShowsAPolicyIdThatIsNotUtf8Replaced) {
  std::array<EndcapStatus, kEndcapCount> status{};
  status[4].seen = true;
  status[4].heartbeat.active_policy_id(kNotUtf8);
  std::string json;
  ASSERT_NO_THROW(json = format_status_json(status, 0));
  EXPECT_NE(json.find(kReplaced), std::string::npos) << json;
}

TEST(WireText, AConsoleReplyCarriesAnAckTextThatIsNotUtf8Replaced) {
  OperatorReply reply;
  EndcapCommandResult r;
  r.endcap = 2;
  r.text = kNotUtf8;
  reply.report.results.push_back(r);
  std::string line;
  ASSERT_NO_THROW(line = encode_reply(reply));
  const OperatorReply got = decode_reply(line);
  ASSERT_EQ(got.report.results.size(), 1U);
  EXPECT_EQ(got.report.results[0].text, kReplaced);
}

}  // namespace
}  // namespace tensegrity::ground
