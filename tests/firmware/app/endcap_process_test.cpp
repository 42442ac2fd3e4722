// SPDX-License-Identifier: Apache-2.0
// End to end: the real `endcap` program on a udp: bus against scripted devices in
// this process, in lockstep. This test plays the HIL: it sends SYNC, relays the
// end cap's frames to the devices and their answers back, and watches the drive
// targets follow the policy given with --policy and --start-on-boot.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include <nlohmann/json.hpp>

#include "firmware/app/endcap_stats.hpp"
#include "firmware/app/policy_store.hpp"
#include "firmware/drivers/pdo_codec.hpp"
#include "firmware/drivers/spool_geometry.hpp"
#include "firmware/hal/crc32.hpp"
#include "firmware/hal/udp_can_bus.hpp"
#include "hil/devices/udp_ports.hpp"
#include "hil/devices/cia402_drive.hpp"
#include "hil/devices/load_cell.hpp"

extern char** environ;

namespace tensegrity::fw {
namespace {

namespace fs = std::filesystem;
namespace sim = tensegrity::hil;  // the emulated devices
using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

// Below the ephemeral range: a port bound to 0 and released for the end cap could
// go to any other socket binding 0 (a DDS participant of a test beside) first.
std::uint16_t free_udp_port() { return sim::free_udp_ports(1).at(0); }

class ChildProcess {
 public:
  explicit ChildProcess(std::vector<std::string> args) {
    // A cross build runs the end cap under qemu-user: no binfmt_misc here.
    if (std::string(ENDCAP_EMULATOR).size() > 0) args.insert(args.begin(), ENDCAP_EMULATOR);
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    if (posix_spawn(&pid_, argv[0], nullptr, nullptr, argv.data(), environ) != 0) pid_ = -1;
  }
  ~ChildProcess() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  pid_t pid() const { return pid_; }
  // SIGTERM, then wait up to `timeout`; -1 if it had to be killed.
  int terminate(std::chrono::milliseconds timeout) {
    ::kill(pid_, SIGTERM);
    const auto give_up = Clock::now() + timeout;
    int status = 0;
    while (Clock::now() < give_up) {
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return -1;
  }
  bool exited_early() {
    int status = 0;
    return ::waitpid(pid_, &status, WNOHANG) == pid_ ? (pid_ = -1, true) : false;
  }

 private:
  pid_t pid_ = -1;
};

TEST(EndcapProcess, LockstepOverUdpFollowsThePolicy) {
  const fs::path dir = fs::temp_directory_path() / ("endcap_e2e_" + std::to_string(std::random_device{}()));
  fs::create_directories(dir);
  const std::uint16_t endcap_port = free_udp_port();
  ASSERT_NE(endcap_port, 0);
  std::string error;
  auto bus = UdpCanBus::open({{"127.0.0.1", endcap_port}, {"127.0.0.1", 0}}, error);
  ASSERT_TRUE(bus) << error;

  // End cap 2 owns cables 4 and 5: square waves in opposite phase.
  json cables = json::array();
  for (int c = 0; c < 24; ++c) {
    const bool odd = c % 2 == 1;
    cables.push_back({{"cable", c}, {"owner", c / 2}, {"rest_lengths_m", {odd ? 1.0 : 0.9, odd ? 0.9 : 1.0}}});
  }
  std::ofstream(dir / "policy.json") << json{
      {"format", "tensegrity-policy/1"},
      {"robot", "superball"},
      {"period_s", 0.4},
      {"complexity", 2},
      {"cables", cables}}.dump();
  const json config = {
      {"format", "tensegrity-endcap/1"},
      {"bus", "udp:127.0.0.1:" + std::to_string(bus->local_port()) + ",bind=127.0.0.1:" + std::to_string(endcap_port)},
      {"nodes", {{"drives", {3, 5}}, {"load_cell", 4}}},
      {"spool", {{"radius_m", 0.01}, {"counts_per_rev", 446464}}},
      {"limits",
       {{"min_rest_length_m", 0.6},
        {"max_rest_length_m", 1.1},
        {"speed_m_per_s", 0.2},
        {"cutoff_tension_n", 400},
        {"hard_limit_tension_n", 500}}},
      {"initial_rest_length_m", 0.95},
      {"storage_dir", (dir / "store").string()},
      {"loop", {{"period_ns", 1'000'000}, {"mode", "lockstep"}}},
      {"timeouts", {{"drive_heartbeat_s", 0.5}, {"load_cell_heartbeat_s", 0.5}, {"load_cell_sample_s", 0.1}}},
  };
  std::ofstream(dir / "endcap.json") << config.dump(2);

  ChildProcess child({ENDCAP_BINARY, "--no-dds", "--id", "2", "--config", (dir / "endcap.json").string(), "--policy",
                      (dir / "policy.json").string(), "--start-on-boot", "--stats-json",
                      (dir / "stats.json").string()});
  ASSERT_GT(child.pid(), 0);

  sim::SimCia402Drive drive0(3);
  sim::SimCia402Drive drive1(5);
  sim::SimLoadCell load_cell(4);
  load_cell.sample.tension_mn = {100'000, 100'000};
  sim::SimNode* devices[] = {&drive0, &drive1, &load_cell};
  sim::FrameOut out;
  const auto t0 = Clock::now();
  const auto now_ns = [&] { return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0).count(); };
  const auto flush = [&] {
    for (const CanFrame& f : out) bus->send(f);
    out.clear();
  };
  // The devices boot once the end cap is listening; its bring-up resets them anyway.
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  for (sim::SimNode* d : devices) d->boot(now_ns(), out);
  flush();

  const SpoolGeometry spool{0.01, 446464.0, 0.95};
  std::int32_t min0 = 0, max0 = 0, min1 = 0, max1 = 0;
  // A square wave through a rate limiter is a triangle: count its turning points.
  struct Turns {
    std::int32_t last = 0;
    int direction = 0;
    int turns = 0;
    void add(std::int32_t v) {
      const int d = v > last ? 1 : (v < last ? -1 : 0);
      if (d != 0 && direction != 0 && d != direction) ++turns;
      if (d != 0) direction = d;
      last = v;
    }
  } turns0, turns1;
  std::uint64_t rpdos = 0;
  const auto deadline = t0 + std::chrono::seconds(7);
  bool enough = false;
  while (Clock::now() < deadline && !enough) {
    ASSERT_FALSE(child.exited_early()) << "endcap exited; see its stderr above";
    // One HIL tick: device heartbeats, SYNC to everyone, then relay until quiet.
    for (sim::SimNode* d : devices) d->tick(now_ns(), out);
    const CanFrame sync = canopen::encode_sync();
    for (sim::SimNode* d : devices) d->on_frame(sync, now_ns(), out);
    bus->send(sync);
    flush();
    const auto tick_end = Clock::now() + std::chrono::milliseconds(1);
    CanFrame f;
    while (Clock::now() < tick_end) {
      if (bus->receive(f, 200'000) != CanResult::ok) continue;
      if ((f.id & 0x780U) == 0x200U) ++rpdos;
      for (sim::SimNode* d : devices) d->on_frame(f, now_ns(), out);
      flush();
    }
    if (drive0.state() == canopen::Cia402State::operation_enabled) {
      min0 = std::min(min0, drive0.target_counts());
      max0 = std::max(max0, drive0.target_counts());
      min1 = std::min(min1, drive1.target_counts());
      max1 = std::max(max1, drive1.target_counts());
      turns0.add(drive0.target_counts());
      turns1.add(drive1.target_counts());
    }
    // From 0.95 m each motor moves 4 cm (0.2 m/s for half of the 0.4 s period) one
    // way, then back, in opposite directions: the table is playing.
    const std::int32_t three_cm = spool.counts_from_rest_length(0.92);
    enough = max0 >= three_cm && -min1 >= three_cm && turns0.turns >= 2 && turns1.turns >= 2;
  }
  EXPECT_TRUE(enough) << "drive 0 counts [" << min0 << ", " << max0 << "], drive 1 [" << min1 << ", " << max1
                      << "], turns " << turns0.turns << "/" << turns1.turns << ", RPDOs seen " << rpdos;
  EXPECT_EQ(drive1.state(), canopen::Cia402State::operation_enabled);
  EXPECT_EQ(drive0.mode(), canopen::kModeCyclicSynchronousPosition);
  // Never beyond the table's range (0.9..1.0 m), whatever the rate limiter did.
  EXPECT_LE(max0, spool.counts_from_rest_length(0.9) + 1);
  EXPECT_GE(min1, spool.counts_from_rest_length(1.0) - 1);

  // While it runs: a snapshot each second (what a killed end cap leaves behind).
  const auto snapshot_deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (!std::filesystem::exists(dir / "stats.json") && std::chrono::steady_clock::now() < snapshot_deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const app::EndcapStats running = app::load_stats(dir / "stats.json");
  EXPECT_FALSE(running.final);
  EXPECT_EQ(running.endcap, 2);
  EXPECT_FALSE(running.cycle.has_value()) << "timing is reported at exit";
  EXPECT_EQ(child.terminate(std::chrono::seconds(2)), 0);
  const app::EndcapStats stats = app::load_stats(dir / "stats.json");
  EXPECT_TRUE(stats.final) << "--stats-json rewritten at exit";
  EXPECT_EQ(stats.endcap, 2);
  EXPECT_GT(stats.cycles, 100U);
  EXPECT_GE(stats.cycles, running.cycles);
  EXPECT_EQ(stats.cycles, stats.syncs_received) << "lockstep: one cycle per SYNC";
  EXPECT_EQ(stats.fault, "none");
  ASSERT_TRUE(stats.cycle.has_value());
  EXPECT_GT(stats.cycle->count, 0U);
  EXPECT_EQ(stats.link.host_losses, 0U) << "no DDS link in this run";
  // --policy FILE stored the table with its own identity, as one record.
  FileStorage storage(dir / "store");
  app::PolicyStore store(storage, 2, core::MotorLimits{});
  app::StoredTable stored;
  std::string report;
  ASSERT_TRUE(store.load(stored, report)) << report;
  EXPECT_EQ(stored.identity.policy_id, "file:policy");
  EXPECT_EQ(stored.identity.policy_version, 0U);
  EXPECT_EQ(stored.identity.checksum, crc32(app::encode_table(app::StoredTable{0, stored.table, {}})));
  EXPECT_DOUBLE_EQ(stored.table.period_s, 0.4);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace tensegrity::fw

namespace {
// The program's stderr and exit status for `args`, as a shell runs it.
std::pair<std::string, int> run_endcap(const std::string& args) {
  const std::string emulator = ENDCAP_EMULATOR;
  const std::string cmd = (emulator.empty() ? "" : emulator + " ") + ENDCAP_BINARY + " " + args + " 2>&1 >/dev/null";
  std::string out;
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (pipe == nullptr) return {"popen failed", -1};
  char buf[256];
  while (std::fgets(buf, sizeof buf, pipe) != nullptr) out += buf;
  const int status = ::pclose(pipe);
  return {out, WIFEXITED(status) ? WEXITSTATUS(status) : -1};
}
}  // namespace

// The node refuses a rejoin wait under a host's hearing window (comms::validate); the
// program says so up front, naming its flag, before anything starts.
TEST(EndcapProcess, ARejoinWaitTheNodeRefusesIsRefusedByItsFlag) {
  for (const char* bad : {"1", "-5", "5000", "abc"}) {
    const auto [err, status] =
        run_endcap(std::string("--id 0 --config ") + ENDCAP_EXAMPLE_CONFIG + " --unheard-rejoin-s " + bad);
    EXPECT_NE(status, 0) << bad;
    EXPECT_NE(err.find("--unheard-rejoin-s: expected 0 (never) or 3..3600 s, got " + std::string(bad)),
              std::string::npos)
        << err;
  }
}
