// SPDX-License-Identifier: Apache-2.0
// The DDS link end to end, with real Fast DDS participants on loopback in separate
// processes: 12 end-cap nodes (comms_test_node, stub control loops) and the host
// (ground::Station in this process, or ground_test_host). Each test uses its own
// domain (ctest runs tests in parallel) and removes any shared-memory file its
// processes left (the profiles turn SHM off, so there should be none).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <regex>
#include <set>
#include <vector>

#include "firmware/comms/wire/reasons.hpp"
#include "core/fault.hpp"
#include "ground/command.hpp"
#include "ground/upload.hpp"
#include "msgs/dds.hpp"
#include "tests/ground/subprocess.hpp"

namespace tensegrity::ground {
namespace {

namespace fs = std::filesystem;
using fw::comms::CommandReason;
using fw::comms::PolicyReason;
using test::Subprocess;

std::set<std::string> shm_files() {
  std::set<std::string> out;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator("/dev/shm", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("fast_datasharing_", 0) == 0 || name.rfind("fastrtps_", 0) == 0) out.insert(name);
  }
  return out;
}

class GroundDds : public ::testing::Test {
 protected:
  void SetUp() override {
    shm_before_ = shm_files();
    dir_ = fs::temp_directory_path() / ("ground_dds_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    robot_ = sim::load_robot(sim::robot_path_named("superball"));
  }
  void TearDown() override {
    nodes_.clear();
    host_.reset();
    station_.reset();
    std::size_t left = 0;
    for (const auto& name : shm_files()) {
      if (shm_before_.count(name) == 0) {
        fs::remove(fs::path("/dev/shm") / name);
        ++left;
      }
    }
    if (left > 0) std::printf("removed %zu shared-memory files left in /dev/shm\n", left);
    fs::remove_all(dir_);
  }

  Subprocess& start_nodes(int domain, std::vector<std::string> extra = {}) {
    std::vector<std::string> argv{COMMS_TEST_NODE, "--domain", std::to_string(domain)};
    argv.insert(argv.end(), extra.begin(), extra.end());
    const std::string tag = std::to_string(nodes_.size());
    nodes_.push_back(
        std::make_unique<Subprocess>(argv, dir_ / ("nodes" + tag + ".out"), dir_ / ("nodes" + tag + ".err")));
    EXPECT_TRUE(nodes_.back()->wait_for_output("READY", std::chrono::seconds(20)));
    return *nodes_.back();
  }
  Station& station(int domain, bool heartbeat = true) {
    StationOptions o;
    o.domain = domain;
    o.publish_heartbeat = heartbeat;
    o.name = "test_station";
    station_ = std::make_unique<Station>(o);
    return *station_;
  }
  static std::int64_t seconds(double s) { return static_cast<std::int64_t>(s * 1e9); }

  sim::Policy make_policy(double shift_m = 0.0) const {
    sim::Policy p;
    p.robot = robot_.name;
    p.period_s = 2.0;
    p.complexity = 8;
    p.provenance.method = "hand";
    p.provenance.robot_hash = robot_.hash;
    for (int c = 0; c < robot_.cable_count(); ++c) {
      sim::CablePolicy cp;
      cp.cable = c;
      cp.owner = robot_.cables[static_cast<std::size_t>(c)].owner;
      for (int k = 0; k < p.complexity; ++k) cp.rest_lengths_m.push_back(0.85 + shift_m + 0.05 * std::sin(k + c));
      p.cables.push_back(cp);
    }
    return p;
  }
  std::vector<msg::PolicyTable_> messages(const sim::Policy& p, std::uint32_t version) const {
    return policy_messages(p, robot_, fw::comms::PolicyIdentity{"test_gait", version, robot_.name, false},
                           random_sequence_base());
  }

  fs::path dir_;
  sim::Robot robot_;
  std::set<std::string> shm_before_;
  std::vector<std::unique_ptr<Subprocess>> nodes_;
  std::unique_ptr<Subprocess> host_;
  std::unique_ptr<Station> station_;
};

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(std::ceil(p * static_cast<double>(v.size()))) - 1;
  return v[std::min(i, v.size() - 1)];
}

TEST_F(GroundDds, UploadToTwelveEndcapsAllAcknowledge) {
  constexpr int kDomain = 151;
  start_nodes(kDomain, {"--quiet"});
  Station& s = station(kDomain);
  ASSERT_TRUE(s.wait_for_endcaps(kAllEndcaps, false, Station::now_ns() + seconds(15)));
  const UploadReport report = upload(s, messages(make_policy(), 1), UploadOptions{});
  std::printf("%s", format_upload_report(report).c_str());
  ASSERT_TRUE(report.all_accepted());
  for (const auto& r : report.results) {
    EXPECT_EQ(r.reason, PolicyReason::accepted);
    EXPECT_EQ(r.active_policy_id, "test_gait");
    EXPECT_EQ(r.active_policy_version, 1U);
  }
  // The same policy again (a retried upload): accepted, nothing changes.
  const UploadReport again = upload(s, messages(make_policy(), 1), UploadOptions{});
  ASSERT_TRUE(again.all_accepted());
  for (const auto& r : again.results) EXPECT_EQ(r.reason, PolicyReason::already_active);

  // Latency: successive versions to all 12, from first write to the last ack.
  std::vector<double> latencies_ms;
  for (std::uint32_t v = 2; v < 42; ++v) {
    const UploadReport r = upload(s, messages(make_policy(0.001 * v), v), UploadOptions{});
    ASSERT_TRUE(r.all_accepted()) << format_upload_report(r);
    double worst = 0.0;
    for (const auto& e : r.results) worst = std::max(worst, e.latency_s);
    latencies_ms.push_back(worst * 1e3);
  }
  std::printf("MEASURE upload_12_latency_ms median=%.2f p99=%.2f max=%.2f n=%zu\n", percentile(latencies_ms, 0.5),
              percentile(latencies_ms, 0.99), percentile(latencies_ms, 1.0), latencies_ms.size());
}

TEST_F(GroundDds, EveryBadPolicyIsRejectedWithItsReasonAndTheOldOneKeepsRunning) {
  constexpr int kDomain = 152;
  start_nodes(kDomain);
  Station& s = station(kDomain);
  ASSERT_TRUE(s.wait_for_endcaps(kAllEndcaps, true, Station::now_ns() + seconds(15)));
  // Before any table: the start is refused with its reason (the loop could not play it).
  const CommandReport early = send_command(s, CommandKind::start, Station::now_ns() + seconds(0.2), {});
  for (const auto& r : early.results) {
    EXPECT_TRUE(r.acked && !r.accepted) << "end cap " << r.endcap;
    EXPECT_EQ(r.reason, CommandReason::no_table) << "end cap " << r.endcap << ": " << r.text;
  }
  ASSERT_TRUE(upload(s, messages(make_policy(), 5), UploadOptions{}).all_accepted());
  const CommandReport start = send_command(s, CommandKind::start, Station::now_ns() + seconds(0.2), {});
  ASSERT_TRUE(start.all_accepted()) << format_command_report(start);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  ASSERT_EQ(s.snapshot()[3].telemetry.mode(), 1U) << "end cap 3 did not start";

  struct Case {
    const char* name;
    void (*tamper)(msg::PolicyTable_&);
    PolicyReason reason;
  };
  static auto re = +[](msg::PolicyTable_& m) { m.checksum(fw::comms::policy_checksum(m)); };
  const Case cases[] = {
      {"wrong end cap",
       [](msg::PolicyTable_& m) {
         m.endcap_id(static_cast<std::int16_t>(m.endcap_id() + 1));
         re(m);
       },
       PolicyReason::wrong_endcap},
      {"wrong count",
       [](msg::PolicyTable_& m) {
         m.motor_count(3);
         re(m);
       },
       PolicyReason::bad_motor_count},
      {"short values",
       [](msg::PolicyTable_& m) {
         m.rest_length_m().pop_back();
         re(m);
       },
       PolicyReason::bad_size},
      {"NaN",
       [](msg::PolicyTable_& m) {
         m.rest_length_m()[1] = std::nan("");
         re(m);
       },
       PolicyReason::non_finite_value},
      {"out of range",
       [](msg::PolicyTable_& m) {
         m.rest_length_m()[1] = 2.5;
         re(m);
       },
       PolicyReason::value_out_of_limits},
      {"bad checksum", [](msg::PolicyTable_& m) { m.checksum(m.checksum() + 1); }, PolicyReason::bad_checksum},
      {"stale version",
       [](msg::PolicyTable_& m) {
         m.policy_version(4);
         re(m);
       },
       PolicyReason::stale_version},
      {"same version, other values",
       [](msg::PolicyTable_& m) {
         m.rest_length_m()[0] += 0.01;
         re(m);
       },
       PolicyReason::stale_version},
      {"wrong message version", [](msg::PolicyTable_& m) { m.format_version(msgs::kFormatVersion + 1); },
       PolicyReason::wrong_format_version},
  };
  for (const Case& c : cases) {
    std::vector<msg::PolicyTable_> all = messages(make_policy(0.02), 5);
    msg::PolicyTable_ bad = all[3];
    c.tamper(bad);
    const UploadReport r = upload(s, {bad}, UploadOptions{});
    ASSERT_EQ(r.results.size(), 1U);
    EXPECT_TRUE(r.results[0].acked) << c.name;
    EXPECT_FALSE(r.results[0].accepted) << c.name;
    EXPECT_EQ(r.results[0].reason, c.reason) << c.name << ": " << r.results[0].text;
    EXPECT_EQ(r.results[0].active_policy_id, "test_gait") << c.name;
    EXPECT_EQ(r.results[0].active_policy_version, 5U) << c.name;
    std::printf("%-28s -> %s: %s\n", c.name, fw::comms::to_string(r.results[0].reason), r.results[0].text.c_str());
  }
  // Still running the old table: telemetry of end cap 3 says so.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const auto snap = s.snapshot();
  ASSERT_TRUE(snap[3].have_telemetry);
  EXPECT_EQ(snap[3].telemetry.mode(), 1U);  // running
  EXPECT_EQ(snap[3].telemetry.active_policy_version(), 5U);
  // A forced older version is taken.
  std::vector<msg::PolicyTable_> forced = policy_messages(
      make_policy(0.03), robot_, fw::comms::PolicyIdentity{"test_gait", 2, robot_.name, true}, random_sequence_base());
  const UploadReport f = upload(s, {forced[3]}, UploadOptions{});
  EXPECT_TRUE(f.all_accepted()) << format_upload_report(f);
}

TEST_F(GroundDds, StartAtHostTimePutsAllTwelveInPhase) {
  constexpr int kDomain = 153;
  // Each end cap's clock is off by up to +-30 s: only the time sync can line them up.
  Subprocess& nodes = start_nodes(kDomain, {"--clock-offset-spread-s", "30"});
  Station& s = station(kDomain);
  ASSERT_TRUE(s.wait_for_endcaps(kAllEndcaps, true, Station::now_ns() + seconds(15)));
  ASSERT_TRUE(upload(s, messages(make_policy(), 1), UploadOptions{}).all_accepted());
  std::this_thread::sleep_for(std::chrono::seconds(1));  // a few more sync samples
  const std::int64_t t = Station::now_ns() + seconds(1.0);
  const CommandReport start = send_command(s, CommandKind::start, t, {});
  ASSERT_TRUE(start.all_accepted()) << format_command_report(start);
  std::map<int, long long> started;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  const std::regex line(R"(STARTED endcap=(\d+) true_ns=(-?\d+))");
  while (started.size() < 12 && std::chrono::steady_clock::now() < deadline) {
    const std::string out = nodes.output();
    for (std::sregex_iterator it(out.begin(), out.end(), line), end; it != end; ++it) {
      started[std::stoi((*it)[1])] = std::stoll((*it)[2]);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_EQ(started.size(), 12U) << nodes.output();
  long long lo = started.begin()->second, hi = lo, worst_vs_t = 0;
  for (const auto& [e, ns] : started) {
    lo = std::min(lo, ns);
    hi = std::max(hi, ns);
    worst_vs_t = std::max(worst_vs_t, std::llabs(ns - t));
  }
  const auto snap = s.snapshot();
  std::int64_t worst_rtt = 0;
  for (const auto& e : snap) worst_rtt = std::max(worst_rtt, e.heartbeat.clock_round_trip_ns());
  std::printf("MEASURE start_skew_us spread=%.1f worst_vs_target=%.1f worst_sync_rtt=%.1f\n",
              static_cast<double>(hi - lo) / 1e3, static_cast<double>(worst_vs_t) / 1e3,
              static_cast<double>(worst_rtt) / 1e3);
  // Loopback: the bound is half the round trip (tens of microseconds); 2 ms leaves
  // room for a loaded 2-core machine.
  EXPECT_LT(hi - lo, 2'000'000);
  EXPECT_LT(worst_vs_t, 2'000'000);
}

TEST_F(GroundDds, TelemetryArrivesAtTheConfiguredRate) {
  constexpr int kDomain = 154;
  // 40 Hz, not the 100 Hz default: the pacing below must come from the option.
  constexpr double kPeriodMs = 25.0;
  start_nodes(kDomain, {"--telemetry-hz", "40", "--quiet"});
  Station& s = station(kDomain);
  ASSERT_TRUE(s.wait_for_endcaps(kAllEndcaps, false, Station::now_ns() + seconds(15)));
  // Intervals between consecutive samples (seq + 1), on the end cap's own loop clock.
  std::mutex m;
  std::array<std::vector<double>, kEndcapCount> intervals_ms;
  std::array<std::pair<std::uint32_t, std::int64_t>, kEndcapCount> previous{};
  s.on_telemetry([&](const msg::Telemetry_& t, std::int64_t) {
    if (t.endcap_id() < 0 || t.endcap_id() >= kEndcapCount) return;
    const auto i = static_cast<std::size_t>(t.endcap_id());
    std::lock_guard lock(m);
    if (previous[i].second != 0 && t.seq() == previous[i].first + 1) {
      intervals_ms[i].push_back(static_cast<double>(t.loop_time_ns() - previous[i].second) / 1e6);
    }
    previous[i] = {t.seq(), t.loop_time_ns()};
  });
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const auto a = s.snapshot();
  const std::int64_t t0 = Station::now_ns();
  std::this_thread::sleep_for(std::chrono::seconds(4));
  const auto b = s.snapshot();
  s.on_telemetry(nullptr);
  const double dt = static_cast<double>(Station::now_ns() - t0) / 1e9;
  double total = 0.0, total_sent = 0.0;
  std::uint64_t gaps = 0;
  std::lock_guard lock(m);
  for (int e = 0; e < kEndcapCount; ++e) {
    const auto i = static_cast<std::size_t>(e);
    total += static_cast<double>(b[i].telemetry_count - a[i].telemetry_count) / dt;
    gaps += b[i].telemetry_gaps - a[i].telemetry_gaps;
    const double sent_s = static_cast<double>(b[i].telemetry.loop_time_ns() - a[i].telemetry.loop_time_ns()) / 1e9;
    ASSERT_GT(sent_s, 1.0) << "end cap " << e << " stopped sending";
    const double sent_hz = static_cast<double>(b[i].telemetry.seq() - a[i].telemetry.seq()) / sent_s;
    total_sent += sent_hz;
    // Rates are timing, and CI's 2 shared cores starve the 12 nodes (they once sent
    // only 53-58 of 100 Hz: a node skips samples it is late for rather than burst),
    // so the assertions are about pacing, which load cannot fake: the node never
    // sends faster than configured, and the typical gap on its own clock is the
    // configured period. The rates are the MEASURE line.
    EXPECT_LT(sent_hz, 1000.0 / kPeriodMs * 1.1) << "end cap " << e;
    EXPECT_GT(sent_hz, 1.0) << "end cap " << e << ": (almost) stalled";
    auto& v = intervals_ms[i];
    ASSERT_GE(v.size(), 10U) << "end cap " << e << ": too few consecutive samples received";
    std::sort(v.begin(), v.end());
    const double p25 = v[v.size() / 4];
    EXPECT_NEAR(p25, kPeriodMs, 0.3 * kPeriodMs) << "end cap " << e << ": typical sample gap, ms";
  }
  std::printf("MEASURE telemetry at 40 Hz: sent %.1f samples/s, received %.1f (%.1f kB/s payload ~%zu B) lost=%llu\n",
              total_sent, total, total * 220 / 1e3, std::size_t{220}, static_cast<unsigned long long>(gaps));
}

TEST_F(GroundDds, KillingTheHostLeavesEndcapsBehavingAsConfigured) {
  constexpr int kDomain = 155;
  start_nodes(kDomain, {"--host-loss", "continue", "--stop-on-host-loss", "6-11", "--host-timeout-s", "0.5"});
  host_ = std::make_unique<Subprocess>(std::vector<std::string>{GROUND_TEST_HOST, std::to_string(kDomain)},
                                       dir_ / "host.out", dir_ / "host.err");
  ASSERT_TRUE(host_->wait_for_output("READY", std::chrono::seconds(20)));
  Station& s = station(kDomain, /*heartbeat=*/false);  // an observer: must not stand in for the host
  ASSERT_TRUE(s.wait_for_endcaps(kAllEndcaps, true, Station::now_ns() + seconds(15)));
  ASSERT_TRUE(upload(s, messages(make_policy(), 1), UploadOptions{}).all_accepted());
  ASSERT_TRUE(send_command(s, CommandKind::start, Station::now_ns() + seconds(0.2), {}).all_accepted());
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  for (const auto& e : s.snapshot()) {
    EXPECT_EQ(e.heartbeat.mode(), 1U);
    EXPECT_FALSE(e.heartbeat.host_lost());
  }
  host_->kill_hard();
  // Loss is declared 0.5 s after the last host heartbeat; seeing it here also takes
  // the end caps' next heartbeats, which a loaded CI host delays (a fixed 1.5 s once
  // was not enough). Wait for every end cap to report it, up to 10 s.
  auto snap = s.snapshot();
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < give_up &&
         !std::all_of(snap.begin(), snap.end(), [](const auto& e) { return e.heartbeat.host_lost(); })) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    snap = s.snapshot();
  }
  // The stopping end caps stop within their next cycle; give them one more heartbeat.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  snap = s.snapshot();
  for (int e = 0; e < kEndcapCount; ++e) {
    const auto& hb = snap[static_cast<std::size_t>(e)].heartbeat;
    EXPECT_TRUE(hb.host_lost()) << "end cap " << e;
    EXPECT_EQ(hb.host_loss_action(), e >= 6 ? 1U : 0U) << "end cap " << e;
    EXPECT_EQ(snap[static_cast<std::size_t>(e)].telemetry.mode(), e >= 6 ? 2U : 1U)
        << "end cap " << e << (e >= 6 ? " should have stopped, latched" : " should keep its gait");
    if (e >= 6) {
      EXPECT_EQ(hb.fault(), static_cast<std::uint8_t>(core::FaultCause::host_lost)) << "end cap " << e;
    }
  }
}

// Host loss measured: the host (a process that only sends its heartbeat) is killed
// while the twelve end caps play; each latches host_lost within 1.5 s of the kill
// (the 1 s timeout, the node's check, a loop cycle, and a loaded machine's wake-ups).
// Cuts: TENSEGRITY_HOST_CUTS (default 3; docs/guide/robot.md gives a 50-cut run).
TEST_F(GroundDds, EveryPlayingEndcapLatchesHostLostWithinOneAndAHalfSecondsOfTheCut) {
  constexpr int kDomain = 178;
  constexpr std::int64_t kBoundNs = 1'500'000'000;
  const char* env = std::getenv("TENSEGRITY_HOST_CUTS");
  const int cuts = env != nullptr ? std::max(1, std::atoi(env)) : 3;
  Subprocess& nodes = start_nodes(kDomain);
  Station& s = station(kDomain, /*heartbeat=*/false);  // an observer, not a host
  std::vector<double> latency_ms;
  for (int cut = 0; cut < cuts; ++cut) {
    host_ = std::make_unique<Subprocess>(std::vector<std::string>{GROUND_TEST_HOST, std::to_string(kDomain)},
                                         dir_ / "host.out", dir_ / "host.err");
    ASSERT_TRUE(host_->wait_for_output("READY", std::chrono::seconds(20)));
    ASSERT_TRUE(s.wait_for_endcaps(kAllEndcaps, true, Station::now_ns() + seconds(15)));
    // Heard by every end cap: a heartbeat sent after this host came up that says so
    // (an older one may predate the last cut's loss).
    const std::int64_t host_up = Station::now_ns();
    const auto hears_host = [&s, host_up] {
      const auto snap = s.snapshot();
      return std::all_of(snap.begin(), snap.end(), [host_up](const auto& e) {
        return e.heartbeat_host_ns > host_up + 250'000'000 && !e.heartbeat.host_lost();
      });
    };
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(15);
    while (!hears_host() && std::chrono::steady_clock::now() < until) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ASSERT_TRUE(hears_host()) << "cut " << cut << ": the end caps never heard the host";
    if (cut == 0) {
      ASSERT_TRUE(upload(s, messages(make_policy(), 1), UploadOptions{}).all_accepted());
    }
    CommandOptions clear;
    ASSERT_TRUE(send_command(s, CommandKind::clear_fault, 0, clear).all_accepted()) << "cut " << cut;
    // A start is judged on the loop's state as the node last saw it: wait for the clear.
    const auto cleared = [&s] {
      const auto snap = s.snapshot();
      return std::all_of(snap.begin(), snap.end(), [](const auto& e) { return e.telemetry.fault() == 0; });
    };
    const auto clear_until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (!cleared() && std::chrono::steady_clock::now() < clear_until) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    const CommandReport started = send_command(s, CommandKind::start, Station::now_ns() + seconds(0.2), {});
    ASSERT_TRUE(started.all_accepted()) << "cut " << cut << "\n" << format_command_report(started);
    std::this_thread::sleep_for(std::chrono::milliseconds(600));
    std::string modes;  // what each end cap's telemetry said just before the cut
    for (const auto& e : s.snapshot()) modes += std::to_string(e.telemetry.mode()) + " ";
    const std::int64_t killed = Station::now_ns();
    host_->kill_hard();
    std::map<int, std::int64_t> lost;
    const std::regex line(R"(HOSTLOST endcap=(\d+) true_ns=(-?\d+))");
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (lost.size() < static_cast<std::size_t>(kEndcapCount) && std::chrono::steady_clock::now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      const std::string text = nodes.output();
      for (std::sregex_iterator it(text.begin(), text.end(), line), end; it != end; ++it) {
        const std::int64_t t = std::stoll((*it)[2]);
        if (t >= killed) lost.emplace(std::stoi((*it)[1]), t);
      }
    }
    ASSERT_EQ(lost.size(), static_cast<std::size_t>(kEndcapCount))
        << "cut " << cut << ": not every end cap latched; modes at the cut: " << modes << "\n"
        << nodes.output().substr(nodes.output().size() > 2000 ? nodes.output().size() - 2000 : 0) << "\n"
        << [this] {
             std::ifstream in(dir_ / "nodes0.err");
             const std::string t((std::istreambuf_iterator<char>(in)), {});
             return t.substr(t.size() > 4000 ? t.size() - 4000 : 0);
           }();
    for (const auto& [e, t] : lost) {
      EXPECT_LE(t - killed, kBoundNs) << "cut " << cut << ", end cap " << e;
      latency_ms.push_back(static_cast<double>(t - killed) / 1e6);
    }
  }
  std::sort(latency_ms.begin(), latency_ms.end());
  std::printf("MEASURE host loss to host_lost latched, %d cut(s) x 12 end caps: median %.0f ms, max %.0f ms\n", cuts,
              latency_ms[latency_ms.size() / 2], latency_ms.back());
}

// An end cap that never hears a host (started on boot, say) judges it lost once its
// boot grace has passed, not never; an observer without a heartbeat of its own does
// not count as a host.
TEST_F(GroundDds, AnEndcapThatNeverHearsAHostJudgesItLostAfterItsBootGrace) {
  constexpr int kDomain = 174;
  const std::int64_t started = Station::now_ns();
  start_nodes(kDomain, {"--endcaps", "0-2", "--host-boot-grace-s", "3"});
  Station& s = station(kDomain, /*heartbeat=*/false);
  ASSERT_TRUE(s.wait_for_endcaps(0b111, false, Station::now_ns() + seconds(15)));
  const auto lost_count = [&s] {
    int n = 0;
    for (int e = 0; e < 3; ++e) n += s.snapshot()[static_cast<std::size_t>(e)].heartbeat.host_lost() ? 1 : 0;
    return n;
  };
  if (Station::now_ns() - started < seconds(2.5)) {
    EXPECT_EQ(lost_count(), 0) << "lost before the grace ran out";
  }
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (lost_count() < 3 && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(lost_count(), 3) << "an end cap never judged the host it never heard lost";

  // A start taken while the host stays lost (from a tool that sends no heartbeat) is
  // stopped at once, not played unwatched: the stop is asked for as long as the loss lasts.
  ASSERT_TRUE(s.wait_for_endcaps(0b111, true, Station::now_ns() + seconds(15)));
  auto tables = messages(make_policy(), 1);
  std::erase_if(tables, [](const msg::PolicyTable_& t) { return t.target_endcap() > 2; });
  ASSERT_TRUE(upload(s, tables, UploadOptions{}).all_accepted());
  CommandOptions co;
  co.endcap_mask = 0b111;
  const std::int64_t start_at = Station::now_ns() + seconds(0.2);
  send_command(s, CommandKind::start, start_at, co);
  const auto latched = [&] {
    int n = 0;
    const std::string text = nodes_.front()->output();
    for (int e = 0; e < 3; ++e) n += text.find("HOSTLOST endcap=" + std::to_string(e) + " ") != std::string::npos;
    return n;
  };
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (latched() < 3 && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(latched(), 3) << "an end cap played on without a host";
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  for (int e = 0; e < 3; ++e) {
    EXPECT_NE(s.snapshot()[static_cast<std::size_t>(e)].telemetry.mode(), 1U) << "end cap " << e << " still playing";
  }
}

// CPU of one end cap's node (every thread but the stub loop: DDS threads and the
// node's own) with telemetry at 100 Hz, from /proc.
double thread_cpu_s(pid_t pid, bool loop) {
  double total = 0.0;
  for (const auto& t : fs::directory_iterator("/proc/" + std::to_string(pid) + "/task")) {
    std::ifstream comm(t.path() / "comm");
    std::string name;
    std::getline(comm, name);
    if ((name == "loop") != loop) continue;
    std::ifstream stat(t.path() / "stat");
    std::string s((std::istreambuf_iterator<char>(stat)), {});
    std::istringstream rest(s.substr(s.rfind(')') + 2));
    std::string field;
    long long utime = 0, stime = 0;
    for (int i = 3; i <= 15; ++i) {
      rest >> field;
      if (i == 14) utime = std::stoll(field);
      if (i == 15) stime = std::stoll(field);
    }
    total += static_cast<double>(utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
  }
  return total;
}

TEST_F(GroundDds, NodeCpuAtOneHundredHertz) {
  constexpr int kDomain = 156;
  Subprocess& node = start_nodes(kDomain, {"--endcaps", "0", "--loop-hz", "1000", "--telemetry-hz", "100", "--quiet"});
  Station& s = station(kDomain);
  ASSERT_TRUE(s.wait_for_endcaps(1, true, Station::now_ns() + seconds(15)));
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const double node0 = thread_cpu_s(node.pid(), false), loop0 = thread_cpu_s(node.pid(), true);
  const std::int64_t t0 = Station::now_ns();
  std::this_thread::sleep_for(std::chrono::seconds(10));
  const double wall = static_cast<double>(Station::now_ns() - t0) / 1e9;
  const double node_pct = (thread_cpu_s(node.pid(), false) - node0) / wall * 100.0;
  const double loop_pct = (thread_cpu_s(node.pid(), true) - loop0) / wall * 100.0;
  std::printf("MEASURE node_cpu_percent_of_one_core=%.2f (stub loop at 1 kHz: %.2f)\n", node_pct, loop_pct);
  EXPECT_LT(node_pct, 25.0);
}

}  // namespace
}  // namespace tensegrity::ground
