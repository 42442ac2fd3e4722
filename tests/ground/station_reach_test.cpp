// SPDX-License-Identifier: Apache-2.0
// A station counts an end cap ready only once what it writes reaches it: heard is
// not enough (msgs/matched_readers.hpp). A "deaf" end cap, publishing heartbeats in
// its partition without a command or policy reader, is heard and not ready; its
// readers made, it is. Domain 172.
#include <gtest/gtest.h>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>

#include <atomic>
#include <chrono>
#include <thread>

#include "ground/station.hpp"
#include "ground/station_keeper.hpp"
#include "msgs/dds.hpp"
#include "msgs/endcap_writers.hpp"
#include "tensegrity_msgs/msg/CommandPubSubTypes.h"
#include "tensegrity_msgs/msg/HeartbeatPubSubTypes.h"
#include "tensegrity_msgs/msg/PolicyTablePubSubTypes.h"

namespace tensegrity::ground {
namespace {

namespace dds = eprosima::fastdds::dds;
namespace m = tensegrity_msgs::msg::dds_;

constexpr int kDomain = 172;
constexpr int kKeeperDomain = 173;
constexpr int kEndcap = 3;
constexpr std::uint16_t kMask = 1U << kEndcap;

std::int64_t after_s(double s) { return Station::now_ns() + static_cast<std::int64_t>(s * 1e9); }

// End cap 3's heartbeat every 50 ms; its order readers only when asked.
class DeafEndcap {
 public:
  explicit DeafEndcap(int domain = kDomain) {
    participant_ = msgs::create_participant(domain, "deaf_endcap", {}, {});
    auto* pub = participant_->create_publisher(msgs::endcap_publisher_qos(kEndcap));
    writer_ = msgs::create_writer(*participant_, *pub, msgs::kEndcapHeartbeatTopic,
                                  dds::TypeSupport(new m::Heartbeat_PubSubType()));
    thread_ = std::thread([this] {
      m::Heartbeat_ hb;
      hb.format_version(msgs::kFormatVersion);
      hb.source(kEndcap);
      hb.life_id(0x1234);
      for (std::uint32_t seq = 1; !stop_; ++seq) {
        hb.seq(seq);
        hb.time_ns(Station::now_ns());
        writer_->write(&hb);
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    });
  }
  ~DeafEndcap() {
    stop_ = true;
    thread_.join();
    msgs::delete_participant(participant_);
  }
  DeafEndcap(const DeafEndcap&) = delete;
  DeafEndcap& operator=(const DeafEndcap&) = delete;
  void listen(const msgs::TopicSpec& spec, dds::TypeSupport type) {
    if (subscriber_ == nullptr) subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
    msgs::create_reader(*participant_, *subscriber_, spec, type, nullptr);
  }

 private:
  dds::DomainParticipant* participant_ = nullptr;
  dds::Subscriber* subscriber_ = nullptr;
  dds::DataWriter* writer_ = nullptr;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

TEST(StationReach, AnEndcapHeardButNotListeningIsNotReadyUntilBothItsReadersMatch) {
  DeafEndcap endcap;
  StationOptions o;
  o.domain = kDomain;
  o.name = "reach_test_station";
  o.serve_time = false;
  Station station(o);
  const std::int64_t give_up = after_s(15);
  while (!station.snapshot()[kEndcap].seen && Station::now_ns() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_TRUE(station.snapshot()[kEndcap].seen) << "the deaf end cap's heartbeats never arrived";
  EXPECT_FALSE(station.wait_for_endcaps(kMask, false, after_s(1.5))) << "heard, yet nothing reaches it";
  EXPECT_EQ(station.reached(), 0U);

  endcap.listen(msgs::kCommandTopic, dds::TypeSupport(new m::Command_PubSubType()));
  EXPECT_FALSE(station.wait_for_endcaps(kMask, false, after_s(1.5))) << "a table would still reach nobody";

  endcap.listen(msgs::kPolicyTableTopic, dds::TypeSupport(new m::PolicyTable_PubSubType()));
  EXPECT_TRUE(station.wait_for_endcaps(kMask, false, after_s(15)));
  EXPECT_EQ(station.reached(), kMask);
}

// The console's keeper judges by linked (heard and reached), so a one-way stalled
// handshake is seen: the end cap counts as missing and fresh participants are tried.
TEST(StationReach, TheKeeperCountsAnEndcapHeardButNotReachedAsMissing) {
  DeafEndcap endcap(kKeeperDomain);
  int made = 0;
  StationKeeper::Options keep;
  keep.expected = kMask;
  keep.stall_s = 0.5;
  keep.trial_s = 1.0;
  StationKeeper keeper(
      [&made] {
        ++made;
        StationOptions o;
        o.domain = kKeeperDomain;
        o.name = "reach_test_keeper";
        o.serve_time = false;
        return std::make_unique<Station>(o);
      },
      keep);
  const auto tick_for = [&keeper](double s) {
    const std::int64_t until = after_s(s);
    while (Station::now_ns() < until) {
      keeper.tick(Station::now_ns());
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  };
  const std::int64_t give_up = after_s(15);
  while (!keeper.current()->snapshot()[kEndcap].seen && Station::now_ns() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_TRUE(keeper.current()->snapshot()[kEndcap].seen) << "the deaf end cap's heartbeats never arrived";
  EXPECT_FALSE(keeper.current()->snapshot()[kEndcap].reached);
  EXPECT_EQ(StationKeeper::linked(*keeper.current(), kMask, Station::now_ns(), 2.0), 0U) << "heard, not reached";
  tick_for(2.0);
  EXPECT_GE(made, 2) << "no fresh participant was tried for an end cap heard but not reached";

  endcap.listen(msgs::kCommandTopic, dds::TypeSupport(new m::Command_PubSubType()));
  endcap.listen(msgs::kPolicyTableTopic, dds::TypeSupport(new m::PolicyTable_PubSubType()));
  const std::int64_t until = after_s(20);
  while (StationKeeper::linked(*keeper.current(), kMask, Station::now_ns(), 2.0) != kMask &&
         Station::now_ns() < until) {
    keeper.tick(Station::now_ns());
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(StationKeeper::linked(*keeper.current(), kMask, Station::now_ns(), 2.0), kMask);
  EXPECT_TRUE(keeper.current()->snapshot()[kEndcap].reached);
}

}  // namespace
}  // namespace tensegrity::ground
