// SPDX-License-Identifier: Apache-2.0
// The --stats-json schema: what the program writes, its readers parse back, and a
// file another build (or a hand) broke is refused naming the field.
#include "firmware/app/endcap_stats.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

namespace tensegrity::fw::app {
namespace {

using ::testing::HasSubstr;

EndcapStats sample(bool final) {
  EndcapStats s;
  s.final = final;
  s.endcap = 7;
  s.mode = "realtime";
  s.rate_hz = 1000.0;
  s.cycles = 12345;
  s.overruns = 3;
  s.syncs_received = 0;
  s.fault = "none";
  s.bring_up = "operational";
  s.vm_rss_kb = 20480;
  s.link = {2, 1, 1, 0};
  if (final) {
    s.cycle = TimingStats{12345, 12.5, 40.0, 90.0};
    s.wakeup_latency = TimingStats{12345, 30.0, 80.0, 200.0};
    s.table = TablePhase{4.0, 9'000'000'000, 1'000'000'000, 8'000'000'000, 123'456'789};
  }
  return s;
}

TEST(EndcapStats, RoundTripsThroughJson) {
  for (bool final : {false, true}) {
    const EndcapStats s = sample(final);
    const EndcapStats back = parse_stats(to_json(s), "t");
    EXPECT_EQ(back.final, final);
    EXPECT_EQ(back.endcap, 7);
    EXPECT_EQ(back.cycles, 12345U);
    EXPECT_EQ(back.link.host_losses, 2U);
    EXPECT_EQ(back.link.link_cuts, 1U);
    EXPECT_EQ(back.cycle.has_value(), final);
    EXPECT_EQ(back.table.has_value(), final);
    if (final) {
      EXPECT_EQ(back.table->loop_clock_origin_ns, 123'456'789);
      EXPECT_DOUBLE_EQ(back.cycle->p99_us, 40.0);
    }
  }
}

TEST(EndcapStats, ErrorsNameTheField) {
  auto error_of = [](nlohmann::json j) {
    try {
      parse_stats(j, "stats.json");
    } catch (const StatsError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  nlohmann::json j = to_json(sample(true));
  EXPECT_THAT(error_of(nlohmann::json::array()), HasSubstr("(top level): must be an object"));
  nlohmann::json bad = j;
  bad["format"] = "tensegrity-endcap-stats/0";
  EXPECT_THAT(error_of(bad), HasSubstr("stats.json: format: expected \"tensegrity-endcap-stats/2\""));
  bad = j;
  bad["link"].erase("host_losses");
  EXPECT_THAT(error_of(bad), HasSubstr("stats.json: link.host_losses: missing"));
  bad = j;
  bad["cycles"] = -1;
  EXPECT_THAT(error_of(bad), HasSubstr("cycles: must be a count"));
  bad = j;
  bad["table"]["period_s"] = 0.0;
  EXPECT_THAT(error_of(bad), HasSubstr("table.period_s: must be > 0"));
  bad = j;
  bad["cycle"]["p50_us"] = "fast";
  EXPECT_THAT(error_of(bad), HasSubstr("cycle.p50_us: must be a number"));
}

TEST(EndcapStats, WriteReplacesTheFileWhole) {
  const auto dir = std::filesystem::temp_directory_path() / ("endcap_stats_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / "stats.json";
  ASSERT_TRUE(write_stats(path, sample(false)));
  ASSERT_TRUE(write_stats(path, sample(true)));
  EXPECT_TRUE(load_stats(path).final);
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".tmp"));
  std::ofstream(path) << "{\"format\": ";
  EXPECT_THROW(load_stats(path), StatsError);
  EXPECT_THROW(load_stats(dir / "absent.json"), StatsError);
  EXPECT_FALSE(write_stats(dir / "no" / "such" / "dir.json", sample(false)));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace tensegrity::fw::app
