// SPDX-License-Identifier: Apache-2.0
// Persistence as one transaction: a real `endcap` process (its DDS node, a
// realtime loop on a UDP bus nobody answers: a table is taken without drives) is
// SIGKILLed at a random moment of an upload, 100 times. After each kill the store
// is read with the code the end cap boots with (app::PolicyStore): it must hold
// the previous table under the previous identity or the new table under the new
// one, never a table under another's name. The next trial's end cap boots from
// it (and may first take an older table still in the writer's history). Uploads alternate between two tables, version v carrying table v % 2, so a
// record's version says which table must be in it. Domain 158.
#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include <nlohmann/json.hpp>

#include "firmware/app/policy_store.hpp"
#include "ground/upload.hpp"
#include "hil/devices/udp_ports.hpp"
#include "robot/policy.hpp"
#include "robot/robot.hpp"
#include "tests/ground/subprocess.hpp"

namespace tensegrity::ground {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using test::Subprocess;

constexpr int kDomain = 158;
constexpr int kTrials = 100;
constexpr int kEndcap = 0;

// Below the ephemeral range: a port bound to 0 and released for the end cap could
// go to any other socket binding 0 (a DDS participant of a test beside) first.
std::uint16_t free_udp_port() { return hil::free_udp_ports(1).at(0); }

TEST(PersistenceKill, RebootsWithTheOldOrTheNewTableEachUnderItsOwnIdentity) {
  const fs::path dir = fs::temp_directory_path() / ("persistence_kill_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::vector<std::uint16_t> ports{free_udp_port(), 9};  // the bus's peer: nobody
  const json config = {
      {"format", "tensegrity-endcap/1"},
      {"bus", "udp:127.0.0.1:" + std::to_string(ports[1]) + ",bind=127.0.0.1:" + std::to_string(ports[0])},
      {"nodes", {{"drives", {1, 3}}, {"load_cell", 2}}},
      {"spool", {{"radius_m", 0.01}, {"counts_per_rev", 446464}}},
      {"limits",
       {{"min_rest_length_m", 0.6},
        {"max_rest_length_m", 1.1},
        {"speed_m_per_s", 0.2},
        {"cutoff_tension_n", 400},
        {"hard_limit_tension_n", 500}}},
      {"initial_rest_length_m", 0.95},
      {"storage_dir", (dir / "store").string()},
      {"loop", {{"period_ns", 4'000'000}, {"mode", "realtime"}}},
  };
  std::ofstream(dir / "endcap.json") << config.dump(2);

  const sim::Robot robot = sim::load_robot(sim::robot_path_named("superball"));
  const sim::Policy gait =
      sim::load_policy(fs::path(TENSEGRITY_SOURCE) / "docs" / "results" / "policies" / "superball-t4-n5.json", robot);
  sim::Policy shifted = gait;
  for (auto& c : shifted.cables) {
    for (double& v : c.rest_lengths_m) v = std::min(v + 0.01, 1.1);
  }
  auto table_message = [&](std::uint32_t version) {
    return policy_messages(version % 2 == 0 ? gait : shifted, robot,
                           fw::comms::PolicyIdentity{"kill_gait", version, robot.name, false},
                           random_sequence_base())[kEndcap];
  };
  std::array<core::EndcapTable, 2> tables{};
  ASSERT_TRUE(fw::comms::to_endcap_table(table_message(0), tables[0]));
  ASSERT_TRUE(fw::comms::to_endcap_table(table_message(1), tables[1]));

  StationOptions o;
  o.domain = kDomain;
  o.name = "persistence_kill_host";
  Station station(o);
  std::mt19937 rng(15);
  std::uniform_int_distribution<int> kill_after_us(0, 40'000);
  int old_kept = 0, new_kept = 0, none = 0;
  std::uint32_t stored_version = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int trial = 0; trial < kTrials; ++trial) {
    const std::int64_t booted = Station::now_ns();
    Subprocess endcap({ENDCAP_BINARY, "--id", std::to_string(kEndcap), "--config", (dir / "endcap.json").string(),
                       "--domain", std::to_string(kDomain), "--insecure"},
                      dir / "endcap.out", dir / "endcap.err");
    // A heartbeat of this boot (the station remembers the previous one's).
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (station.snapshot()[kEndcap].heartbeat_host_ns <= booted && std::chrono::steady_clock::now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    ASSERT_GT(station.snapshot()[kEndcap].heartbeat_host_ns, booted) << "trial " << trial << ": no heartbeat";
    const std::uint32_t version = static_cast<std::uint32_t>(trial) + 1;
    station.write_policy(table_message(version));
    std::this_thread::sleep_for(std::chrono::microseconds(kill_after_us(rng)));
    endcap.kill_hard();

    fw::FileStorage storage(dir / "store");
    fw::app::PolicyStore store(storage, 2, core::MotorLimits{});
    fw::app::StoredTable stored;
    std::string report;
    if (!store.load(stored, report)) {
      ASSERT_EQ(stored_version, 0U) << "trial " << trial << ": a stored table vanished (" << report << ")";
      ++none;
      continue;
    }
    // The end cap may also have taken an older table from the writer's history at
    // boot (transient local): any version from the stored one to this one.
    const std::uint32_t v = stored.identity.policy_version;
    ASSERT_TRUE(v >= stored_version && v <= version) << "trial " << trial << ": version " << v;
    EXPECT_EQ(stored.identity.policy_id, "kill_gait");
    EXPECT_EQ(stored.identity.checksum, table_message(v).checksum()) << "trial " << trial;
    const core::EndcapTable& expected = tables[v % 2];
    bool same = stored.table.complexity == expected.complexity && stored.table.motor_count == expected.motor_count;
    for (std::uint32_t m = 0; same && m < expected.motor_count; ++m) {
      for (std::uint32_t k = 0; k < expected.complexity; ++k) {
        same = same && stored.table.rest_length_m[m][k] == expected.rest_length_m[m][k];
      }
    }
    ASSERT_TRUE(same) << "trial " << trial << ": MIXED: version " << v << "'s identity over the other table";
    (v == version ? new_kept : old_kept) += 1;
    stored_version = v;
  }
  const double total_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("MEASURE persistence_kill trials=%d new=%d old=%d none=%d mixed=0 total_s=%.1f\n", kTrials, new_kept,
              old_kept, none, total_s);
  EXPECT_GT(new_kept, 0) << "no kill came after the commit: the test did not cover that side";
  EXPECT_GT(old_kept + none, 0) << "no kill came before the commit: the test did not cover that side";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace tensegrity::ground
