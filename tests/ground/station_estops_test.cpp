// SPDX-License-Identifier: Apache-2.0
// What a station keeps of each end cap's emergency-stop count (what a clear-fault
// from it will name): within a life the highest count heard wins, since a heartbeat
// read just before an estop can arrive after that estop's ack; a new life replaces
// it whole, lower count or not; a life it has left is never taken back. Stations on
// domains 190 and 205; the second hears a forged end cap (no real ones).
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "core/fault.hpp"
#include "ground/station.hpp"
#include "msgs/dds.hpp"
#include "msgs/endcap_writers.hpp"
#include "tensegrity_msgs/msg/HeartbeatPubSubTypes.h"

namespace tensegrity::ground {
namespace {

namespace dds = eprosima::fastdds::dds;

StationOptions quiet(int domain) {
  StationOptions o;
  o.domain = domain;
  o.publish_heartbeat = false;
  o.serve_time = false;
  return o;
}

TEST(StationEstops, TheHighestCountOfALifeWinsAndANewLifeReplacesIt) {
  Station s(quiet(190));
  EXPECT_EQ(s.snapshot()[3].estops, (fw::comms::EstopCount{})) << "nothing heard yet";
  s.note_estops(3, {0x11, 2});
  EXPECT_EQ(s.snapshot()[3].estops, (fw::comms::EstopCount{0x11, 2}));
  s.note_estops(3, {0x11, 1});  // an older report of the same life, arriving late
  EXPECT_EQ(s.snapshot()[3].estops, (fw::comms::EstopCount{0x11, 2}));
  s.note_estops(3, {0x23, 0});  // the end cap restarted
  EXPECT_EQ(s.snapshot()[3].estops, (fw::comms::EstopCount{0x23, 0}));
  s.note_estops(3, {0x11, 2});  // the dead life's last word, arriving late: not taken back
  EXPECT_EQ(s.snapshot()[3].estops, (fw::comms::EstopCount{0x23, 0}));
  EXPECT_EQ(s.snapshot()[3].stale_life_samples, 1u);
  s.note_estops(12, {0x55, 9});  // no such end cap: ignored, nothing else touched
  s.note_estops(-1, {0x55, 9});
  for (int e = 0; e < kEndcapCount; ++e) {
    if (e == 3) continue;
    EXPECT_EQ(s.snapshot()[static_cast<std::size_t>(e)].estops, (fw::comms::EstopCount{})) << e;
  }
}

// A late heartbeat of an end cap's previous program (a DDS retransmission, a
// receive thread behind) is dropped whole: the station keeps showing the program
// that runs now, not the dead one's estop until the next heartbeat.
TEST(StationEstops, AHeartbeatOfALifeTheEndcapLeftIsDropped) {
  constexpr int kDomain = 205;
  Station s(quiet(kDomain));
  dds::DomainParticipant* forger = msgs::create_participant(kDomain, "forged_endcap", {}, {});
  ASSERT_NE(forger, nullptr);
  auto* pub = forger->create_publisher(msgs::endcap_publisher_qos(3));  // end cap 3's partition
  dds::DataWriter* w = msgs::create_writer(*forger, *pub, msgs::kEndcapHeartbeatTopic,
                                           dds::TypeSupport(new msg::Heartbeat_PubSubType()));
  ASSERT_NE(w, nullptr);
  std::uint32_t seq = 0;
  const auto heartbeat = [&](std::uint32_t life, std::uint32_t estops, core::FaultCause fault) {
    msg::Heartbeat_ hb;
    hb.format_version(msgs::kFormatVersion);
    hb.source(3);
    hb.seq(++seq);
    hb.time_ns(Station::now_ns());
    hb.fault(static_cast<std::uint8_t>(fault));
    hb.life_id(life);
    hb.estops_received(estops);
    w->write(&hb);
  };
  // Best effort: sent again until the station has it (also while still matching).
  const auto until_heard = [&](std::uint32_t life, std::uint32_t estops, core::FaultCause fault) {
    for (int i = 0; i < 200; ++i) {
      heartbeat(life, estops, fault);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      if (s.snapshot()[3].heartbeat.life_id() == life) return true;
    }
    return false;
  };
  ASSERT_TRUE(until_heard(0x11, 1, core::FaultCause::emergency_stop));
  ASSERT_TRUE(until_heard(0x23, 0, core::FaultCause::none));  // restarted: a new program
  // The old program's, late (best effort: sent again until one arrives).
  for (int i = 0; i < 100 && s.snapshot()[3].stale_life_samples == 0; ++i) {
    heartbeat(0x11, 1, core::FaultCause::emergency_stop);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const EndcapStatus now = s.snapshot()[3];
  EXPECT_GE(now.stale_life_samples, 1u);
  EXPECT_EQ(now.heartbeat.life_id(), 0x23u);
  EXPECT_EQ(now.heartbeat.fault(), 0u);
  EXPECT_EQ(now.estops, (fw::comms::EstopCount{0x23, 0}));
  msgs::delete_participant(forger);
}

}  // namespace
}  // namespace tensegrity::ground
