// SPDX-License-Identifier: Apache-2.0
#include "view/replay_data.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "sim/model/benchmark_policy.hpp"
#include "sim/model/episode.hpp"
#include "view/csv_table.hpp"
#include "view/replay_sink.hpp"

namespace tensegrity::view {
namespace {

std::filesystem::path temp(const std::string& name) { return std::filesystem::path(testing::TempDir()) / name; }

TEST(ReplayData, ReadsTheSimulatorsTelemetryAtTheFrameRate) {
  const sim::Robot robot = sim::load_robot(sim::robot_path_named("superball"));
  const auto path = temp("sim.csv");
  sim::BenchmarkController controller;
  sim::EpisodeOptions options;
  options.duration_s = 1.0;
  options.start = sim::StartKind::drop;
  {
    sim::CsvTelemetry telemetry(path.string());
    options.telemetry = &telemetry;
    sim::run_episode(robot, controller, options);
  }
  // The same episode straight into frames: both paths must agree.
  ReplaySink sink;
  options.telemetry = &sink;
  sim::run_episode(robot, controller, options);
  const ReplayFrames direct = sink.take();

  std::vector<std::string> warnings;
  const ReplayFrames f = load_replay_csv(path, robot, warnings);
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ(f.nodes, 12);
  EXPECT_EQ(f.cables, 24);
  EXPECT_TRUE(f.has_energy);
  EXPECT_NEAR(static_cast<double>(f.frames()), 1.0 / kFrameIntervalS, 2.0);
  for (std::size_t k = 1; k < f.frames(); ++k) EXPECT_GE(f.time_s[k] - f.time_s[k - 1], kFrameIntervalS - 1e-6);
  ASSERT_EQ(f.frames(), direct.frames());
  ASSERT_EQ(f.node_m.size(), f.frames() * 36);
  for (std::size_t i = 0; i < f.node_m.size(); i += 97) EXPECT_NEAR(f.node_m[i], direct.node_m[i], 1e-5);
  for (std::size_t i = 0; i < f.tension_n.size(); i += 31) EXPECT_NEAR(f.tension_n[i], direct.tension_n[i], 1e-2);

  const auto j = nlohmann::json::parse(replay_json(f, "sim.csv"));
  EXPECT_EQ(j["frames"], f.frames());
  EXPECT_EQ(j["node_m"].size(), f.frames() * 36);
  EXPECT_EQ(j["tension_n"].size(), f.frames() * 24);
  EXPECT_EQ(j["energy_j"].size(), f.frames() * 3);
  EXPECT_EQ(j["distance_m"][0], 0.0);
}

std::string hil_header(int nodes, int cables) {
  std::string h = "time_s,centre_x_m,centre_y_m,centre_z_m";
  for (int c = 0; c < cables; ++c) h += ",rest_length_m_" + std::to_string(c);
  for (int c = 0; c < cables; ++c) h += ",tension_n_" + std::to_string(c);
  for (int i = 0; i < nodes; ++i) {
    for (const char* a : {"x", "y", "z"}) h += ",node" + std::to_string(i) + "_" + a + "_m";
  }
  return h + "\n";
}

std::string hil_row(double t, int nodes, int cables, double x) {
  std::string r = std::to_string(t) + ",0,0,0";
  for (int c = 0; c < cables; ++c) r += ",0.9";
  for (int c = 0; c < cables; ++c) r += "," + std::to_string(100 + c);
  for (int i = 0; i < nodes; ++i) r += "," + std::to_string(x) + ",0,0.5";
  return r + "\n";
}

TEST(ReplayData, ReadsAHilRecordWithoutEnergy) {
  const sim::Robot robot = sim::load_robot(sim::robot_path_named("superball"));
  const auto path = temp("hil.csv");
  std::ofstream(path) << hil_header(12, 24) << hil_row(0.0, 12, 24, 0.0) << hil_row(0.001, 12, 24, 0.01)
                      << hil_row(0.03, 12, 24, 3.0);
  std::vector<std::string> warnings;
  const ReplayFrames f = load_replay_csv(path, robot, warnings);
  EXPECT_FALSE(f.has_energy);
  ASSERT_EQ(f.frames(), 2U);  // 0.001 s is closer than a frame to 0
  EXPECT_FLOAT_EQ(f.tension_n[5], 105.0F);
  const auto j = nlohmann::json::parse(replay_json(f, "hil.csv"));
  EXPECT_TRUE(j["energy_j"].is_null());
  EXPECT_NEAR(j["distance_m"][1].get<double>(), 3.0, 1e-4);
}

std::string error_of(const std::filesystem::path& path) {
  const sim::Robot robot = sim::load_robot(sim::robot_path_named("superball"));
  std::vector<std::string> warnings;
  try {
    load_replay_csv(path, robot, warnings);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(ReplayData, MissingColumnsAndTimeGoingBackAreNamed) {
  const auto old_record = temp("old.csv");
  std::ofstream(old_record) << "time_s,centre_x_m\n0,1\n";
  EXPECT_NE(error_of(old_record).find("no column node0_x_m"), std::string::npos) << error_of(old_record);
  const auto back = temp("back.csv");
  std::ofstream(back) << hil_header(12, 24) << hil_row(1.0, 12, 24, 0) << hil_row(0.5, 12, 24, 0);
  EXPECT_NE(error_of(back).find("back.csv:3:1 (time_s): time goes back"), std::string::npos) << error_of(back);
  const auto few = temp("few.csv");
  std::ofstream(few) << hil_header(12, 23) << hil_row(0, 12, 23, 0);
  EXPECT_NE(error_of(few).find("no column cable23_rest_length_m (or rest_length_m_23)"), std::string::npos);
}

}  // namespace
}  // namespace tensegrity::view
