// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/node/node_config.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace tensegrity::fw::comms {
namespace {

std::string error_of(double unheard_rejoin_s) {
  EndcapNodeConfig c;
  c.unheard_rejoin_s = unheard_rejoin_s;
  try {
    validate(c);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(NodeConfig, TheUnheardRejoinWaitIsZeroOrLongerThanTheHostsHearingWindow) {
  EXPECT_EQ(error_of(0.0), "");  // never
  EXPECT_EQ(error_of(3.0), "");
  EXPECT_EQ(error_of(20.0), "");
  EXPECT_EQ(error_of(3600.0), "");
  // Shorter than a host's 2 s window plus a heartbeat would churn; negative, too long
  // or not a number is a typo.
  for (const double bad : {-1.0, 1.0, 2.9, 3601.0, std::nan(""), static_cast<double>(INFINITY)}) {
    const std::string e = error_of(bad);
    EXPECT_NE(e.find("unheard_rejoin_s"), std::string::npos) << bad << ": " << e;
    EXPECT_NE(e.find("0 (never) or 3..3600"), std::string::npos) << bad << ": " << e;
  }
}

TEST(NodeConfig, TheEndcapIdIsOneOfTheRobotsTwelve) {
  // A host's heard mask and the telemetry writers know ids 0..11 only: an end cap
  // with id 12 could never be named and would rejoin for ever.
  for (const int id : {0, 11}) {
    EndcapNodeConfig c;
    c.endcap_id = id;
    EXPECT_NO_THROW(validate(c)) << id;
  }
  for (const int id : {-1, 12, 15}) {
    EndcapNodeConfig c;
    c.endcap_id = id;
    try {
      validate(c);
      ADD_FAILURE() << id << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("endcap_id = " + std::to_string(id) + ": expected 0..11"), std::string::npos)
          << e.what();
    }
  }
}

TEST(NodeConfig, TheDefaultsAreValid) { EXPECT_NO_THROW(validate(EndcapNodeConfig{})); }

// Stop is the default: an end cap left without its host holds, latched.
TEST(NodeConfig, HostLossStopsByDefaultAndTheBootGraceIsNoShorterThanTheTimeout) {
  const EndcapNodeConfig defaults;
  EXPECT_EQ(defaults.host_loss, HostLossAction::stop);
  EndcapNodeConfig c;
  c.host_boot_grace_s = c.host_timeout_s;
  EXPECT_NO_THROW(validate(c));
  for (const double bad : {0.5, 0.0, -1.0, std::nan("")}) {
    c.host_boot_grace_s = bad;
    try {
      validate(c);
      ADD_FAILURE() << bad << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("host_boot_grace_s"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace tensegrity::fw::comms
