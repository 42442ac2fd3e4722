// SPDX-License-Identifier: Apache-2.0
// The DDS link end to end with the real firmware: 12 `endcap` programs
// (firmware/endcap with its real DDS node, realtime loop on a UDP CAN bus),
// each with its emulated drives and load cell (endcap_device_sim), and the host
// side through the `tensegrity` program: upload, start, status --once, with a
// console running as the operator's host. An observer Station in this process (no
// heartbeat of its own) watches telemetry and measures the upload latency to the 12
// real end caps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <random>
#include <regex>

#include <nlohmann/json.hpp>

#include "ground/upload.hpp"
#include "hil/process_launcher.hpp"
#include "robot/policy.hpp"
#include "robot/robot.hpp"
#include "tests/ground/subprocess.hpp"

namespace tensegrity::ground {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using test::Subprocess;

constexpr int kDomain = 157;  // unique per DDS test: ctest runs tests in parallel

std::string read(const fs::path& file) {
  std::ifstream in(file);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(std::ceil(p * static_cast<double>(v.size()))) - 1;
  return v[std::min(i, v.size() - 1)];
}

class RealEndcaps : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("endcap_e2e_" + std::to_string(std::random_device{}()));
    fs::create_directories(dir_);
    // The end caps take their domain from the environment, as on the robot.
    ::setenv("TENSEGRITY_DOMAIN", std::to_string(kDomain).c_str(), 1);
    // The HIL launcher's ports: below the ephemeral range, so that no socket binding
    // port 0 (a DDS participant's sender) takes one before the programs bind them.
    // All at once: a port is free again as soon as it is chosen, so two picks made
    // before the first end cap has bound its ports can return the same one
    // ("Address already in use", seen once in 17 runs under load).
    ports_ = hil::free_udp_ports(2 * kEndcapCount);
    // Unsecured, explicitly: twelve separate end-cap processes with DDS Security
    // leave one unauthenticated now and then (docs/guide/security.md); the secured link
    // is tested in security_dds_test.cpp and hil_dds_test.cpp.
  }
  void TearDown() override {
    // End caps first: a device simulator gone first would fault them (noise in the logs).
    for (auto& e : endcaps_) {
      if (e) e->stop();
    }
    endcaps_.clear();
    devices_.clear();
    console_.reset();
    observer_.reset();
    if (HasFailure()) {
      for (int e = 0; e < kEndcapCount; ++e) {
        std::printf("--- endcap %d stderr (tail)\n%s", e,
                    tail(read(dir_ / ("endcap" + std::to_string(e) + ".err"))).c_str());
      }
    }
    fs::remove_all(dir_);
  }
  static std::string tail(const std::string& s) { return s.size() > 1500 ? s.substr(s.size() - 1500) : s; }

  void start_endcap(int e) {
    const std::string tag = std::to_string(e);
    const std::uint16_t endcap_port = ports_[2 * e];
    const std::uint16_t device_port = ports_[2 * e + 1];
    const json config = {
        {"format", "tensegrity-endcap/1"},
        {"bus", "udp:127.0.0.1:" + std::to_string(device_port) + ",bind=127.0.0.1:" + std::to_string(endcap_port)},
        {"nodes", {{"drives", {1, 3}}, {"load_cell", 2}}},  // endcap_device_sim's node ids
        {"spool", {{"radius_m", 0.01}, {"counts_per_rev", 446464}}},
        {"limits",
         {{"min_rest_length_m", 0.6},
          {"max_rest_length_m", 1.1},
          {"speed_m_per_s", 0.2},
          {"cutoff_tension_n", 400},
          {"hard_limit_tension_n", 500}}},
        {"initial_rest_length_m", 0.95},
        {"storage_dir", (dir_ / ("store" + tag)).string()},
        // What is under test is the DDS link, not the bus timing: a 250 Hz loop and
        // device timeouts of seconds keep 24 processes on two shared cores from
        // tripping sensor_timeout / drive_lost when the machine is busy (seen at
        // load average 50 with 1 kHz and 0.5-1 s).
        {"loop", {{"period_ns", 4'000'000}, {"mode", "realtime"}}},
        {"timeouts",
         {{"drive_heartbeat_s", 3.0},
          {"load_cell_heartbeat_s", 3.0},
          {"load_cell_sample_s", 2.0},
          // Seen in a fresh-clone CI run: a 20 ms position gap (the default) latched
          // stale_position on one end cap.
          {"drive_position_s", 2.0},
          {"drive_consumer_heartbeat_s", 1.0}}},
    };
    const fs::path config_file = dir_ / ("endcap" + tag + ".json");
    std::ofstream(config_file) << config.dump(2);
    devices_.push_back(std::make_unique<Subprocess>(
        std::vector<std::string>{ENDCAP_DEVICE_SIM, std::to_string(device_port), std::to_string(endcap_port), "300"},
        dir_ / ("devices" + tag + ".out"), dir_ / ("devices" + tag + ".err")));
    endcaps_.push_back(std::make_unique<Subprocess>(
        std::vector<std::string>{ENDCAP_BINARY, "--id", tag, "--config", config_file.string(), "--insecure"},
        dir_ / ("endcap" + tag + ".out"), dir_ / ("endcap" + tag + ".err")));
  }

  std::string seen_text() const {
    std::string s;
    const auto status = observer_->snapshot();
    for (int e = 0; e < kEndcapCount; ++e) s += status[static_cast<std::size_t>(e)].seen ? "+" : "-";
    return s;
  }

  // Runs `tensegrity ARGS... --domain D` to the end: exit code, stdout in `out`.
  int tensegrity(std::vector<std::string> args, std::string& out, std::string* err = nullptr) {
    args.insert(args.begin(), TENSEGRITY_CLI);
    args.insert(args.end(), {"--domain", std::to_string(kDomain), "--insecure"});
    const fs::path o = dir_ / "cli.out", e = dir_ / "cli.err";
    Subprocess cli(args, o, e);
    const int rc = cli.wait_exit(std::chrono::seconds(60));
    out = read(o);
    const std::string errors = read(e);
    if (err != nullptr) *err = errors;
    std::printf("$ tensegrity %s ... -> %d\n%s%s", args[1].c_str(), rc, out.c_str(), errors.c_str());
    return rc;
  }

  // Waits until `pred` holds for every end cap's latest status (or the timeout).
  template <typename Pred>
  bool wait_all(Pred pred, double timeout_s) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    for (;;) {
      const auto snap = observer_->snapshot();
      if (std::all_of(snap.begin(), snap.end(), pred)) return true;
      if (std::chrono::steady_clock::now() > deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }

  fs::path dir_;
  std::vector<std::uint16_t> ports_;  // end cap e: bus port 2e, its devices 2e + 1
  std::vector<std::unique_ptr<Subprocess>> devices_;
  std::vector<std::unique_ptr<Subprocess>> endcaps_;
  std::unique_ptr<Station> observer_;
  std::unique_ptr<Subprocess> console_;
};

TEST_F(RealEndcaps, TwelveEndcapProcessesTakeAnUploadStartAndStreamTelemetry) {
  for (int e = 0; e < kEndcapCount; ++e) start_endcap(e);
  StationOptions o;
  o.domain = kDomain;
  o.name = "e2e_observer";
  o.publish_heartbeat = false;  // an observer: the operator's console is the host
  observer_ = std::make_unique<Station>(o);
  const std::int64_t t0 = Station::now_ns();
  ASSERT_TRUE(observer_->wait_for_endcaps(kAllEndcaps, false, t0 + 20'000'000'000))
      << "not every end cap's DDS node came up: " << seen_text();
  // The end caps stop, latched, once no host is heard (host_lost): `upload` and `start`
  // exit, so the operator's console keeps the host heartbeat, as on the robot.
  console_ = std::make_unique<Subprocess>(
      std::vector<std::string>{TENSEGRITY_CLI, "console", "--insecure", "--domain", std::to_string(kDomain), "--socket",
                               (dir_ / "console" / "console.sock").string()},
      dir_ / "console.out", dir_ / "console.err", "/dev/null");
  ASSERT_TRUE(console_->wait_for_output("hears 12 of 12", std::chrono::seconds(30)))
      << console_->output() << read(dir_ / "console.err");
  std::printf("MEASURE discovery of 12 end-cap processes: %.0f ms\n",
              static_cast<double>(Station::now_ns() - t0) / 1e6);

  // 0. A start before any policy is refused with its reason, not acked and left idle.
  ASSERT_TRUE(wait_all(
      [](const EndcapStatus& s) {
        return s.have_telemetry && s.telemetry.drives_enabled() && s.telemetry.fault() == 0;
      },
      15.0))
      << "drives not enabled (or a fault latched) on some end cap";
  std::string refused;
  EXPECT_EQ(tensegrity({"start", "--at", "+1", "--timeout", "10"}, refused), 1);
  std::size_t no_table = 0;
  for (std::size_t at = refused.find("no policy table loaded"); at != std::string::npos;
       at = refused.find("no policy table loaded", at + 1)) {
    ++no_table;
  }
  EXPECT_EQ(no_table, static_cast<std::size_t>(kEndcapCount)) << refused;

  // 1. Upload through the program an operator uses.
  const fs::path policy = fs::path(TENSEGRITY_SOURCE) / "docs" / "results" / "policies" / "superball-t4-n5.json";
  std::string out;
  ASSERT_EQ(
      tensegrity({"upload", policy.string(), "--id", "e2e_gait", "--policy-version", "3", "--timeout", "20"}, out), 0);
  EXPECT_NE(out.find("all 12 end caps accepted"), std::string::npos);
  EXPECT_TRUE(wait_all(
      [](const EndcapStatus& s) {
        return s.have_telemetry && s.telemetry.active_policy_id().to_string() == "e2e_gait" &&
               s.telemetry.active_policy_version() == 3U;
      },
      5.0))
      << "the end caps' telemetry does not report the uploaded policy";

  // 2. Upload latency to the 12 real end caps (idle loops take a table at once):
  // the same ground::upload code, successive versions, first write to last ack.
  const sim::Robot robot = sim::load_robot(sim::robot_path_named("superball"));
  const sim::Policy gait = sim::load_policy(policy, robot);
  std::vector<double> latencies_ms;
  for (std::uint32_t v = 4; v < 34; ++v) {
    const auto tables = policy_messages(gait, robot, fw::comms::PolicyIdentity{"e2e_gait", v, robot.name, false},
                                        random_sequence_base());
    UploadOptions options;
    options.timeout_s = 20.0;  // a latency figure, not a deadline: a slow one is measured, not failed
    const UploadReport r = upload(*observer_, tables, options);
    ASSERT_TRUE(r.all_accepted()) << format_upload_report(r);
    double worst = 0.0;
    for (const auto& e : r.results) worst = std::max(worst, e.latency_s);
    latencies_ms.push_back(worst * 1e3);
  }
  std::printf("MEASURE upload_12_real_endcaps_latency_ms median=%.2f p99=%.2f max=%.2f n=%zu\n",
              percentile(latencies_ms, 0.5), percentile(latencies_ms, 0.99), percentile(latencies_ms, 1.0),
              latencies_ms.size());

  // 3. Start, once every end cap has brought its drives up (CiA 402 over the bus).
  ASSERT_TRUE(wait_all([](const EndcapStatus& s) { return s.have_telemetry && s.telemetry.drives_enabled(); }, 15.0))
      << "drives not enabled on every end cap";
  ASSERT_EQ(tensegrity({"start", "--at", "+1", "--timeout", "10"}, out), 0);

  // 4. Telemetry: every end cap runs the table; commanded rest lengths move.
  std::mutex m;
  std::array<double, kEndcapCount> lo{}, hi{};
  std::array<std::uint64_t, kEndcapCount> running_samples{};
  std::array<std::uint32_t, kEndcapCount> first_seq{}, last_seq{};
  lo.fill(10.0);
  observer_->on_telemetry([&](const msg::Telemetry_& t, std::int64_t) {
    if (t.endcap_id() < 0 || t.endcap_id() >= kEndcapCount || t.mode() != 1) return;
    const auto i = static_cast<std::size_t>(t.endcap_id());
    std::lock_guard lock(m);
    lo[i] = std::min(lo[i], t.commanded_rest_length_m()[0]);
    hi[i] = std::max(hi[i], t.commanded_rest_length_m()[0]);
    if (running_samples[i]++ == 0) first_seq[i] = t.seq();
    last_seq[i] = t.seq();
  });
  const bool all_running =
      wait_all([](const EndcapStatus& s) { return s.have_telemetry && s.telemetry.mode() == 1U; }, 10.0);
  const auto window_start = std::chrono::steady_clock::now();
  std::this_thread::sleep_for(std::chrono::seconds(2));  // 2 s of playing, from the last one's start
  {
    const auto snap = observer_->snapshot();
    std::lock_guard lock(m);
    const double window_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - window_start).count();
    std::uint32_t slowest = ~0U;
    for (int e = 0; e < kEndcapCount; ++e) slowest = std::min(slowest, last_seq[e] - first_seq[e]);
    // The quantity asserted below (sequence span of the running samples received, which
    // may begin a little before the window) per second of the window: a margin, not a rate meter.
    std::printf(
        "MEASURE running_telemetry_sent_slowest_endcap_hz=%.1f (span %u over %.2f s; configured 100, asserted span > "
        "50)\n",
        static_cast<double>(slowest) / window_s, slowest, window_s);
    for (int e = 0; e < kEndcapCount; ++e) {
      const auto i = static_cast<std::size_t>(e);
      const std::string seen = " (all running: " + std::to_string(all_running) + ", telemetry samples " +
                               std::to_string(snap[i].telemetry_count) + ", lost " +
                               std::to_string(snap[i].telemetry_gaps) + ", last mode " +
                               std::to_string(unsigned{snap[i].telemetry.mode()}) + ")";
      // Sent (by sequence number) is the end cap's doing; received is a best-effort
      // reader's on a loaded 2-core machine, which may drop many: ask only for some.
      EXPECT_GT(last_seq[i] - first_seq[i], 50U)
          << "end cap " << e << ": too little telemetry sent in mode running" << seen;
      EXPECT_GE(running_samples[i], 5U) << "end cap " << e << ": too little telemetry received in mode running" << seen;
      // 0.2 m/s for 2 s toward a table 0.6..0.96 m: well over 1 cm.
      EXPECT_GT(hi[i] - lo[i], 0.01) << "end cap " << e << ": commanded rest length of motor 0 did not move" << seen;
    }
  }
  observer_->on_telemetry(nullptr);

  // 5. The operator's view agrees.
  ASSERT_EQ(tensegrity({"status", "--once", "--json", "--timeout", "5"}, out), 0);
  const json status = json::parse(out);
  ASSERT_EQ(status["endcaps"].size(), 12U);
  EXPECT_TRUE(status["missing"].empty());
  for (const auto& e : status["endcaps"]) {
    EXPECT_EQ(e["state"], "running") << e.dump();
    EXPECT_EQ(e["fault"], "-") << e.dump();
    EXPECT_EQ(e["active_policy"], "e2e_gait") << e.dump();
  }
  ASSERT_EQ(tensegrity({"stop", "--timeout", "10"}, out), 0);

  // 6. Each end cap shuts down cleanly on SIGTERM while the host still answers its
  // time-sync requests (a reply racing the node's teardown used to end in SIGSEGV).
  // The exit code is what is checked, not the time to it: on this loaded 2-core VM
  // one end cap was still not reaped 3 s after SIGTERM in 2 runs of 44, and the one
  // inspected had already exited (a zombie: its threads gone from user space).
  for (int e = 0; e < kEndcapCount; ++e) {
    EXPECT_EQ(endcaps_[static_cast<std::size_t>(e)]->stop(std::chrono::seconds(15)), 0)
        << "end cap " << e << " exit status";
  }
}

}  // namespace
}  // namespace tensegrity::ground
