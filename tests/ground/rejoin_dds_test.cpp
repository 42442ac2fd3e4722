// SPDX-License-Identifier: Apache-2.0
// The end cap's side of a stalled link (firmware/comms/node/node_rejoin.cpp), with a real
// end-cap node (comms_test_node, end cap 3) and hosts in this process. A stalled
// security handshake cannot be made to order, so its symptom is forged: a host whose
// heartbeat names other end caps but never this one. Such a host makes the end cap
// join again, and the new participant is heard and obeys an emergency stop (also
// secured: it authenticates afresh); a host that hears nobody, or a second host that
// hears the end cap, makes it stay.
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <thread>

#include "ground/command.hpp"
#include "ground/keystore.hpp"
#include "ground/station.hpp"
#include "ground/upload.hpp"
#include "msgs/dds.hpp"
#include "msgs/security.hpp"
#include "robot/policy.hpp"
#include "robot/robot.hpp"
#include "tensegrity_msgs/msg/HeartbeatPubSubTypes.h"
#include "tests/ground/subprocess.hpp"

namespace tensegrity::ground {
namespace {

namespace fs = std::filesystem;
namespace dds = eprosima::fastdds::dds;
using test::Subprocess;

constexpr int kEndcap = 3;
constexpr double kRejoinS = 3.0;  // the smallest wait the node accepts
constexpr const char* kRejoinLine = "a new DDS participant (rejoin";
constexpr const char* kRetireLine = "the old one closed";

// A host that publishes its heartbeat at 5 Hz naming the end caps in `names`,
// whatever it hears: the forged symptom of a handshake stalled in one direction.
class NamingHost {
 public:
  NamingHost(int domain, std::uint16_t names, const fs::path& enclave_dir = {}) : names_(names) {
    participant_ = msgs::create_participant(domain, "naming_host", {}, enclave_dir);
    auto* pub = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
    writer_ = msgs::create_writer(*participant_, *pub, msgs::kHostHeartbeatTopic,
                                  dds::TypeSupport(new msg::Heartbeat_PubSubType()));
    thread_ = std::thread([this] {
      for (std::uint32_t seq = 1; !stop_.load(); ++seq) {
        msg::Heartbeat_ hb;
        hb.format_version(msgs::kFormatVersion);
        hb.source(-1);
        hb.seq(seq);
        hb.time_ns(Station::now_ns());
        hb.heard_endcaps(names_.load());
        writer_->write(&hb);
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
      }
    });
  }
  ~NamingHost() {
    stop_.store(true);
    thread_.join();
    msgs::delete_participant(participant_);
  }
  void name(std::uint16_t names) { names_.store(names); }

 private:
  std::atomic<std::uint16_t> names_;
  std::atomic<bool> stop_{false};
  dds::DomainParticipant* participant_ = nullptr;
  dds::DataWriter* writer_ = nullptr;
  std::thread thread_;
};

class EndcapRejoin : public ::testing::Test {
 public:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("endcap_rejoin_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    // A node that made new participants must still stop cleanly: a listener left on
    // a closed participant would crash it (or, in the asan preset, fail it) here.
    if (node_) {
      EXPECT_EQ(node_->stop(std::chrono::seconds(10)), 0) << log();
    }
    node_.reset();
    fs::remove_all(dir_);
  }
  void start_node(int domain, const fs::path& keystore = {}, const std::vector<std::string>& more = {}) {
    std::vector<std::string> argv{COMMS_TEST_NODE,         "--domain",           std::to_string(domain),  "--endcaps",
                                  std::to_string(kEndcap), "--unheard-rejoin-s", std::to_string(kRejoinS)};
    if (!keystore.empty()) argv.insert(argv.end(), {"--keystore", keystore.string()});
    argv.insert(argv.end(), more.begin(), more.end());
    node_ = std::make_unique<Subprocess>(argv, dir_ / "node.out", dir_ / "node.err");
    ASSERT_TRUE(node_->wait_for_output("READY", std::chrono::seconds(30)));
  }
  std::string log() const {
    std::ifstream in(dir_ / "node.err");
    return {std::istreambuf_iterator<char>(in), {}};
  }
  int rejoins() const {
    const std::string text = log();
    int n = 0;
    for (auto at = text.find(kRejoinLine); at != std::string::npos; at = text.find(kRejoinLine, at + 1)) ++n;
    return n;
  }
  // Whether `line` is in the node's log within `timeout_s`.
  bool wait_for_line(const std::string& line, double timeout_s) const {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (log().find(line) == std::string::npos) {
      if (std::chrono::steady_clock::now() > until) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return true;
  }
  bool wait_for_rejoins(int n, std::chrono::seconds timeout) const {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (rejoins() < n) {
      if (std::chrono::steady_clock::now() > until) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return true;
  }

  fs::path dir_;
  std::unique_ptr<Subprocess> node_;
};

constexpr std::uint16_t kOthers = kAllEndcaps & ~(1U << kEndcap);

StationOptions station_options(int domain, const char* name, const fs::path& enclave_dir, bool heartbeat) {
  StationOptions o;
  o.domain = domain;
  o.name = name;
  o.publish_heartbeat = heartbeat;
  o.enclave_dir = enclave_dir;
  return o;
}

// From a station that hears end cap 3, its emergency stop is acked within 0.5 s, as
// on any link (tests/ground/estop_dds_test.cpp bounds it at about 0.4 s).
void estop_lands(Station& station, const EndcapRejoin& t, const char* when) {
  ASSERT_TRUE(station.wait_for_endcaps(1U << kEndcap, false, Station::now_ns() + 30'000'000'000)) << t.log();
  CommandOptions c;
  c.endcap_mask = 1U << kEndcap;
  c.retry_interval_s = kEstopRetryIntervalS;
  const CommandReport estop = send_command(station, CommandKind::emergency_stop, 0, c);
  EXPECT_TRUE(estop.all_accepted()) << t.log();
  ASSERT_EQ(estop.results.size(), 1U);
  std::printf("estop %s: acked after %.1f ms\n", when, estop.results[0].latency_s * 1e3);
  EXPECT_LT(estop.results[0].latency_s, 0.5);
}

// A command while both participants listen (the old one muted): each that takes it acks
// on both, so the station hears two acks, both by the new one (one if each acked only on
// its own). The old one closes 1 s later at the earliest; the acks take a millisecond.
void a_command_in_the_overlap_is_acked_on_both(Station& station, const EndcapRejoin& t) {
  ASSERT_EQ(t.log().find(kRetireLine), std::string::npos) << "the overlap is over already\n" << t.log();
  msg::Command_ cmd;
  cmd.format_version(msgs::kFormatVersion);
  cmd.seq(0x7E57);
  cmd.kind(static_cast<std::uint8_t>(CommandKind::emergency_stop));
  cmd.endcap_mask(1U << kEndcap);
  cmd.issued_host_time_ns(Station::now_ns());
  station.take_command_acks();
  station.write_command(cmd);  // once: a retry would be acked again
  int acks = 0;
  for (const std::int64_t until = Station::now_ns() + 500'000'000; Station::now_ns() < until;) {
    station.wait_for_command_acks(until);
    for (const auto& ack : station.take_command_acks())
      acks += ack.seq() == cmd.seq() && ack.endcap_id() == kEndcap && ack.accepted();
  }
  EXPECT_EQ(acks, 2) << "one per participant that took it, each on the heard one too\n" << t.log();
}

// A table uploaded while both participants listen reaches both (or, on a link
// stalled one way, only the old one): it is acked and handed to the loop once.
void upload_lands_once(Station& station, const EndcapRejoin& t) {
  const fs::path file = fs::path(TENSEGRITY_SOURCE) / "docs" / "results" / "policies" / "superball-t4-n5.json";
  const sim::Robot robot = sim::load_robot(sim::robot_path_for_policy(file));
  auto tables =
      policy_messages(sim::load_policy(file, robot), robot,
                      fw::comms::PolicyIdentity{"overlap_gait", 1, robot.name, false}, random_sequence_base());
  std::erase_if(tables, [](const auto& m) { return m.target_endcap() != kEndcap; });
  const UploadReport report = upload(station, tables, UploadOptions{});
  EXPECT_TRUE(report.all_accepted()) << format_upload_report(report) << t.log();
  std::this_thread::sleep_for(std::chrono::seconds(1));  // a second copy, if any, has arrived
  const std::string text = t.log();
  constexpr const char* kAccepted = "policy overlap_gait v1 accepted";
  EXPECT_NE(text.find(kAccepted), std::string::npos) << text;
  EXPECT_EQ(text.find(kAccepted), text.rfind(kAccepted)) << text;
  EXPECT_EQ(text.find("rejected"), std::string::npos) << text;
}

// Both tests below: a host that hears others but not end cap 3 makes it join again,
// after the wait and then after twice the wait; a station beside it then hears the new
// participant (which no longer rejoins) and its emergency stop lands.
void joins_again_and_obeys(EndcapRejoin& t, int domain, const fs::path& keystore) {
  auto enclave = [&](msgs::Role role, int id) {
    return keystore.empty() ? fs::path() : msgs::enclave_dir(keystore, msgs::enclave_name(role, id));
  };
  t.start_node(domain, keystore);
  const auto t0 = std::chrono::steady_clock::now();
  NamingHost deaf(domain, kOthers, enclave(msgs::Role::ground, -1));
  ASSERT_TRUE(t.wait_for_rejoins(1, std::chrono::seconds(40))) << t.log();
  // The old participant keeps listening while no host hears the new one.
  EXPECT_EQ(t.log().find(kRetireLine), std::string::npos) << t.log();
  // Not before the wait: the end cap gave the host kRejoinS to hear it.
  EXPECT_GE(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), kRejoinS - 0.3);
  EXPECT_NE(t.log().find("rejoin 1"), std::string::npos) << t.log();

  // Unanswered, it joins again after twice the wait (not in a tight loop).
  const auto t1 = std::chrono::steady_clock::now();
  ASSERT_TRUE(t.wait_for_rejoins(2, std::chrono::seconds(40))) << t.log();
  EXPECT_GE(std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count(), 2 * kRejoinS - 0.5);

  // Two participants listen now (the old one until a host names the new one): a
  // policy upload and an emergency stop from a station that names nobody, and so
  // retires nothing, land on them once and in bounded time.
  {
    Station silent(station_options(domain, "rejoin_test_silent_station", enclave(msgs::Role::ground, -1), false));
    upload_lands_once(silent, t);
    estop_lands(silent, t, "while two participants listen");
    EXPECT_EQ(t.log().find(kRetireLine), std::string::npos) << t.log();
  }

  // A real station beside the deaf host hears the new participant and names it: no
  // more rejoins, and an emergency stop lands on it.
  Station station(station_options(domain, "rejoin_test_station", enclave(msgs::Role::ground, -1), true));
  ASSERT_TRUE(station.wait_for_endcaps(1U << kEndcap, false, Station::now_ns() + 30'000'000'000)) << t.log();
  // Named by the station (past the host's 2 s window), the new one is known to be
  // heard: the old one closes, once.
  EXPECT_TRUE(t.wait_for_line(kRetireLine, 10.0)) << t.log();
  estop_lands(station, t, "on the rejoined end cap");
  const int after = t.rejoins();
  std::this_thread::sleep_for(std::chrono::duration<double>(3 * kRejoinS));
  EXPECT_EQ(t.rejoins(), after) << t.log();
  const std::string text = t.log();
  EXPECT_EQ(text.find(kRetireLine), text.rfind(kRetireLine)) << text;
  // The old participant heard the host all along: no host loss, secured or not.
  EXPECT_EQ(text.find("host LOST"), std::string::npos) << text;
}

TEST_F(EndcapRejoin, AnEndcapNoHostHearsJoinsAgainAndItsNewParticipantObeys) { joins_again_and_obeys(*this, 189, {}); }

TEST_F(EndcapRejoin, ASecuredEndcapJoinsAgainAndAuthenticatesAfresh) {
  create_keystore(dir_ / "keystore");
  joins_again_and_obeys(*this, 193, dir_ / "keystore");
}

TEST_F(EndcapRejoin, AHostThatHearsNobodyOrAnotherThatHearsTheEndcapKeepsItsParticipant) {
  constexpr int kDomain = 191;
  start_node(kDomain);
  const auto wait = std::chrono::duration<double>(2.5 * kRejoinS);
  // A host that hears no end cap (a tool just started, or a host whose own side is
  // stalled) is no evidence against this end cap; bits of end caps the robot does
  // not have (12-15) are not end caps heard.
  NamingHost fresh(kDomain, 0xF000);
  std::this_thread::sleep_for(wait);
  EXPECT_EQ(rejoins(), 0) << log();
  // One host naming it is enough, whatever the others say.
  NamingHost hearing(kDomain, kAllEndcaps);
  std::this_thread::sleep_for(std::chrono::seconds(1));  // discovered
  fresh.name(kOthers);
  std::this_thread::sleep_for(wait);
  EXPECT_EQ(rejoins(), 0) << log();
  // The control: without it, the same deaf host makes the end cap join again.
  hearing.name(kOthers);
  EXPECT_TRUE(wait_for_rejoins(1, std::chrono::seconds(20))) << log();
}

// A one-way stall made, not forged: S seconds in, end cap 3's participant stops
// sending (comms_test_node --dds-mute-after-s: its transport drops what it sends)
// and still hears. A real station, which hears end cap 2 beside it, stops naming it;
// end cap 3 joins again, the station hears it again and the old participant closes.
// An emergency stop sent while it is muted is acted on at once (it still hears) and
// acked once the new participant speaks. Secured, the new participant authenticates
// afresh with the station.
void muted_joins_again(EndcapRejoin& t, int domain, const fs::path& keystore) {
  const fs::path station_enclave =
      keystore.empty() ? fs::path() : msgs::enclave_dir(keystore, msgs::enclave_name(msgs::Role::ground, -1));
  std::vector<std::string> secured;
  if (!keystore.empty()) secured = {"--keystore", keystore.string()};
  t.start_node(domain, keystore, {"--dds-mute-after-s", "4"});
  std::vector<std::string> argv{COMMS_TEST_NODE, "--domain", std::to_string(domain), "--endcaps", "2"};
  argv.insert(argv.end(), secured.begin(), secured.end());
  Subprocess other(argv, t.dir_ / "other.out", t.dir_ / "other.err");
  ASSERT_TRUE(other.wait_for_output("READY", std::chrono::seconds(30)));
  Station station(station_options(domain, "rejoin_test_station", station_enclave, true));
  constexpr std::uint16_t kBoth = (1U << 2) | (1U << kEndcap);
  ASSERT_TRUE(station.wait_for_endcaps(kBoth, false, Station::now_ns() + 30'000'000'000)) << t.log();
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while ((station.heard(Station::now_ns(), 1.0) & (1U << kEndcap)) != 0 && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_NE(t.log().find("MUTED"), std::string::npos) << t.log();
  ASSERT_EQ(station.heard(Station::now_ns(), 1.0) & kBoth, 1U << 2) << t.log();
  ASSERT_EQ(t.rejoins(), 0) << t.log();

  auto estop = std::async(std::launch::async, [&station] {
    CommandOptions c;
    c.endcap_mask = 1U << kEndcap;
    c.timeout_s = 30.0;
    c.retry_interval_s = kEstopRetryIntervalS;
    return send_command(station, CommandKind::emergency_stop, 0, c);
  });
  EXPECT_TRUE(t.node_->wait_for_output("ESTOPPED", std::chrono::milliseconds(500))) << t.log();
  const CommandReport report = estop.get();
  EXPECT_TRUE(report.all_accepted()) << t.log();
  ASSERT_EQ(report.results.size(), 1U);
  std::printf("estop while muted: acted on at once, acked after %.1f s (rejoin wait %.0f s)\n",
              report.results[0].latency_s, kRejoinS);
  EXPECT_GT(report.results[0].latency_s, 1.0);  // not by the muted participant
  EXPECT_EQ(t.rejoins(), 1) << t.log();
  a_command_in_the_overlap_is_acked_on_both(station, t);

  EXPECT_TRUE(t.wait_for_line(kRetireLine, 15.0)) << t.log();
  estop_lands(station, t, "on the end cap that was muted");
  EXPECT_EQ(t.rejoins(), 1) << t.log();
  EXPECT_EQ(t.log().find("host LOST"), std::string::npos) << t.log();
}

TEST_F(EndcapRejoin, AMutedEndcapJoinsAgainAndIsHeardAgain) { muted_joins_again(*this, 199, {}); }

TEST_F(EndcapRejoin, AMutedSecuredEndcapJoinsAgainAndAuthenticatesAfresh) {
  create_keystore(dir_ / "keystore");
  muted_joins_again(*this, 201, dir_ / "keystore");
}

// The wait doubles while a deaf host goes unanswered (above), so that it cannot make
// the end cap churn. A host that is lost and then heard again (restarted, or another
// one) is not known to be that host: it gets the first wait, not the grown one (and a
// loss after the host named others but not end cap 3 makes one participant at once).
TEST_F(EndcapRejoin, AHostHeardAgainAfterALossGetsTheFirstWait) {
  constexpr int kDomain = 197;
  start_node(kDomain);
  {
    NamingHost deaf(kDomain, kOthers);
    // After kRejoinS, then 2 x kRejoinS: the next wait would be 4 x kRejoinS.
    ASSERT_TRUE(wait_for_rejoins(2, std::chrono::seconds(40))) << log();
    // Unheard on its new participant too, past the host's 2 s window.
    std::this_thread::sleep_for(std::chrono::milliseconds(2500));
  }
  ASSERT_TRUE(wait_for_line("host LOST", 10.0)) << log();
  // A host lost after it heard others but not end cap 3 for longer than its window
  // may have dropped it: one more participant at the loss (note_host_lost).
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const int at_loss = rejoins();
  EXPECT_EQ(at_loss, 3) << log();
  EXPECT_NE(log().find("it dropped this participant"), std::string::npos) << log();
  const auto back = std::chrono::steady_clock::now();
  NamingHost deaf_again(kDomain, kOthers);
  ASSERT_TRUE(wait_for_rejoins(at_loss + 1, std::chrono::seconds(40))) << log();
  const double waited_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - back).count();
  EXPECT_GE(waited_s, kRejoinS - 0.5);
  EXPECT_LT(waited_s, 4 * kRejoinS - 2.0) << log();  // the grown wait, less a discovery's margin
}

// A host that dies while it hears end cap 3 named it to the end: its loss is no
// evidence against the end cap, which waits for it with the participant it has.
TEST_F(EndcapRejoin, AHostThatDiesHearingTheEndcapIsWaitedFor) {
  constexpr int kDomain = 203;
  start_node(kDomain);
  {
    NamingHost hearing(kDomain, kAllEndcaps);
    std::this_thread::sleep_for(std::chrono::seconds(3));
  }
  ASSERT_TRUE(wait_for_line("host LOST", 10.0)) << log();
  std::this_thread::sleep_for(std::chrono::seconds(2));
  EXPECT_EQ(rejoins(), 0) << log();
}

// A hung control loop withholds the end cap's heartbeat on purpose (the host must
// see it as dead): no host names it then, and a new participant would not change
// that. The same deaf host that makes a healthy end cap join again after kRejoinS
// (above) must not make this one churn while its loop hangs; once the loop moves
// again, the wait starts afresh and the deaf host gets its rejoin.
TEST_F(EndcapRejoin, AnEndcapWhoseLoopHungKeepsItsParticipant) {
  constexpr int kDomain = 195;
  constexpr double kHangS = 10.0;  // more than 3 waits
  start_node(kDomain, {}, {"--loop-stall-after-s", "0.5", "--loop-stall-for-s", std::to_string(kHangS)});
  NamingHost deaf(kDomain, kOthers);
  ASSERT_TRUE(wait_for_line("control loop STALLED", 5.0)) << log();
  ASSERT_TRUE(wait_for_line("control loop progressing again", kHangS + 5.0)) << log();
  EXPECT_EQ(rejoins(), 0) << log();
  const auto resumed = std::chrono::steady_clock::now();
  ASSERT_TRUE(wait_for_rejoins(1, std::chrono::seconds(15))) << log();
  EXPECT_GE(std::chrono::duration<double>(std::chrono::steady_clock::now() - resumed).count(), kRejoinS - 0.5);
}

}  // namespace
}  // namespace tensegrity::ground
