// SPDX-License-Identifier: Apache-2.0
// The view is read-only: its HTTP server refuses every method but GET, and its DDS
// participant, seen from another participant on the domain, has readers (telemetry,
// end-cap heartbeats) and no writer at all: no command, no policy table, not even a
// host heartbeat. Also: a telemetry sample written on the domain reaches the
// page's event stream, mapped to the robot's cables.
#include <gtest/gtest.h>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/rtps/reader/ReaderDiscoveryInfo.h>
#include <fastdds/rtps/writer/WriterDiscoveryInfo.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <fstream>
#include <mutex>
#include <set>
#include <thread>

#include "hil/dds_domain.hpp"
#include "msgs/dds.hpp"
#include "msgs/endcap_writers.hpp"
#include "tensegrity_msgs/msg/TelemetryPubSubTypes.h"
#include "view/csv_table.hpp"
#include "view/live_bridge.hpp"
#include "view/server.hpp"
// After Eigen (through robot/robot.hpp): it includes <resolv.h>, whose `_res` macro
// breaks Eigen's parameters of that name.
#include <httplib.h>

namespace tensegrity::view {
namespace {

namespace dds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

TEST(ViewServer, AnswersGetAndRefusesEveryOtherMethod) {
  const auto three = std::filesystem::path(testing::TempDir()) / "three";
  std::filesystem::create_directories(three / "build");
  std::ofstream(three / "build" / "three.module.js") << "export const REVISION = 'test';\n";
  ServerOptions o;
  o.port = 0;
  o.three_dir = three;
  ViewServer server(o);
  server.json("/api/mode", [] { return std::string("{\"mode\":\"test\"}"); });
  server.json("/api/pending", [] { return std::optional<std::string>(); });
  server.start();
  httplib::Client client("127.0.0.1", server.port());
  EXPECT_EQ(client.Get("/api/mode")->body, "{\"mode\":\"test\"}");
  EXPECT_EQ(client.Get("/api/pending")->status, 503);
  EXPECT_EQ(client.Get("/")->status, 200);
  EXPECT_NE(client.Get("/")->body.find("/js/main.js"), std::string::npos);  // the embedded page
  EXPECT_EQ(client.Get("/js/main.js")->status, 200);
  EXPECT_EQ(client.Get("/three/build/three.module.js")->body, "export const REVISION = 'test';\n");
  EXPECT_EQ(client.Get("/nothing")->status, 404);
  for (const char* path : {"/", "/api/mode", "/api/live/events", "/anything"}) {
    EXPECT_EQ(client.Post(path, "{\"kind\":2}", "application/json")->status, 405) << path;
    EXPECT_EQ(client.Put(path, "{}", "application/json")->status, 405) << path;
    EXPECT_EQ(client.Delete(path)->status, 405) << path;
  }
}

TEST(ViewServer, SaysWhereThreeJsIsMissing) {
  ServerOptions o;
  o.three_dir = "/nonexistent/three";
  try {
    ViewServer server(o);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("libjs-three"), std::string::npos);
  }
}

// What another participant on the domain learns about the view's endpoints.
class Discovery final : public dds::DomainParticipantListener {
 public:
  void on_publisher_discovery(dds::DomainParticipant*, rtps::WriterDiscoveryInfo&& info) override {
    if (info.status != rtps::WriterDiscoveryInfo::DISCOVERED_WRITER) return;
    std::lock_guard lock(mutex_);
    writers.emplace_back(info.info.guid().guidPrefix, info.info.topicName().to_string());
  }
  void on_subscriber_discovery(dds::DomainParticipant*, rtps::ReaderDiscoveryInfo&& info) override {
    if (info.status != rtps::ReaderDiscoveryInfo::DISCOVERED_READER) return;
    std::lock_guard lock(mutex_);
    readers.emplace_back(info.info.guid().guidPrefix, info.info.topicName().to_string());
  }
  std::set<std::string> topics(bool of_writers, const rtps::GuidPrefix_t& prefix) {
    std::lock_guard lock(mutex_);
    std::set<std::string> out;
    for (const auto& [p, t] : of_writers ? writers : readers) {
      if (p == prefix) out.insert(t);
    }
    return out;
  }

 private:
  std::mutex mutex_;
  std::vector<std::pair<rtps::GuidPrefix_t, std::string>> writers, readers;
};

TEST(LiveBridge, HasNoWriterAndForwardsTelemetryToThePage) {
  const hil::DomainLease lease;  // a domain of this test's own
  Discovery discovery;
  dds::DomainParticipant* peer = msgs::create_participant(lease.domain(), "view-test-peer");
  peer->set_listener(&discovery);
  // End cap 3's reports come from end cap 3's partition; an impostor writing from
  // end cap 5's partition claims to be end cap 3.
  dds::Publisher* publisher = peer->create_publisher(msgs::endcap_publisher_qos(3));
  dds::Publisher* impostor_publisher = peer->create_publisher(msgs::endcap_publisher_qos(5));
  dds::DataWriter* writer =
      msgs::create_writer(*peer, *publisher, msgs::kTelemetryTopic,
                          dds::TypeSupport(new tensegrity_msgs::msg::dds_::Telemetry_PubSubType()));
  dds::DataWriter* impostor =
      msgs::create_writer(*peer, *impostor_publisher, msgs::kTelemetryTopic,
                          dds::TypeSupport(new tensegrity_msgs::msg::dds_::Telemetry_PubSubType()));
  const sim::Robot robot = sim::load_robot(sim::robot_path_named("superball"));
  EventHub hub;
  std::uint64_t cursor = hub.head();
  std::uint64_t skipped = 0;
  {
    LiveOptions options;
    options.domain = lease.domain();
    options.status_rate_hz = 4.0;
    LiveBridge bridge(robot, options, hub);
    const rtps::GuidPrefix_t view = bridge.participant().guid().guidPrefix;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(15);
    const std::set<std::string> expected{msgs::kTelemetryTopic.name, msgs::kEndcapHeartbeatTopic.name};
    while (discovery.topics(false, view) != expected && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    EXPECT_EQ(discovery.topics(false, view), expected);

    tensegrity_msgs::msg::dds_::Telemetry_ t;
    t.format_version(msgs::kFormatVersion);
    t.endcap_id(3);
    t.seq(7);
    t.host_time_ns(LiveBridge::now_ns());
    t.motor_count(2);
    t.tension_n() = std::array<double, 4>{123.0, 45.0, 0.0, 0.0};
    tensegrity_msgs::msg::dds_::Telemetry_ forged = t;
    forged.seq(99);
    std::string got;
    int written = 0;  // until the writer matches the bridge's reader, samples may or may not arrive
    while (got.find("event: telemetry") == std::string::npos && std::chrono::steady_clock::now() < deadline) {
      impostor->write(&forged);
      writer->write(&t);
      ++written;
      got += hub.take(&cursor, 200, &skipped);
    }
    for (int i = 0; i < 5; ++i) {
      impostor->write(&forged);
      got += hub.take(&cursor, 100, &skipped);
    }
    EXPECT_EQ(got.find("\"seq\":99"), std::string::npos) << "the view showed end cap 5's writer speaking for end cap 3";
    const std::vector<int> cables = robot.cables_of(3);
    const std::string expected_cables =
        "\"cables\":[" + std::to_string(cables[0]) + "," + std::to_string(cables[1]) + "],\"tension_n\":[123,45]";
    EXPECT_NE(got.find("\"e\":3,\"seq\":7"), std::string::npos) << got;
    EXPECT_NE(got.find(expected_cables), std::string::npos) << got;
    // Every sample end cap 3 wrote and nothing the impostor wrote is counted.
    const nlohmann::json status = nlohmann::json::parse(bridge.status_json());
    const int counted = status.at("endcaps").at(3).at("telemetry").get<int>();
    EXPECT_GE(counted, 1);
    EXPECT_LE(counted, written);
    EXPECT_EQ(status.at("endcaps").at(5).at("telemetry").get<int>(), 0);
    // Readers were discovered above; had the view any writer, it would be by now.
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    EXPECT_TRUE(discovery.topics(true, view).empty()) << "the view writes on " << *discovery.topics(true, view).begin();
  }
  peer->set_listener(nullptr);
  msgs::delete_participant(peer);
}

}  // namespace
}  // namespace tensegrity::view
