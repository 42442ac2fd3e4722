// SPDX-License-Identifier: Apache-2.0
// What a station keeps of each end cap's emergency-stop count (what a clear-fault
// from it will name): within a life the highest count heard wins, since a heartbeat
// read just before an estop can arrive after that estop's ack; a new life replaces
// it whole, lower count or not. A participant on domain 190, no end caps.
#include <gtest/gtest.h>

#include "ground/station.hpp"

namespace tensegrity::ground {
namespace {

TEST(StationEstops, TheHighestCountOfALifeWinsAndANewLifeReplacesIt) {
  StationOptions o;
  o.domain = 190;
  o.publish_heartbeat = false;
  o.serve_time = false;
  Station s(o);
  EXPECT_EQ(s.snapshot()[3].estops, (fw::comms::EstopCount{})) << "nothing heard yet";
  s.note_estops(3, {0x11, 2});
  EXPECT_EQ(s.snapshot()[3].estops, (fw::comms::EstopCount{0x11, 2}));
  s.note_estops(3, {0x11, 1});  // an older report of the same life, arriving late
  EXPECT_EQ(s.snapshot()[3].estops, (fw::comms::EstopCount{0x11, 2}));
  s.note_estops(3, {0x23, 0});  // the end cap restarted
  EXPECT_EQ(s.snapshot()[3].estops, (fw::comms::EstopCount{0x23, 0}));
  s.note_estops(12, {0x55, 9});  // no such end cap: ignored, nothing else touched
  s.note_estops(-1, {0x55, 9});
  for (int e = 0; e < kEndcapCount; ++e) {
    if (e == 3) continue;
    EXPECT_EQ(s.snapshot()[static_cast<std::size_t>(e)].estops, (fw::comms::EstopCount{})) << e;
  }
}

}  // namespace
}  // namespace tensegrity::ground
