// SPDX-License-Identifier: Apache-2.0
// `hil --record` and `sim --telemetry` write one run-record schema
// (sim/model/run_record.hpp), so the view and tools/ read both by the same names.
#include "hil/recorder.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "hil/hil_error.hpp"
#include "robot/robot.hpp"
#include "sim/model/telemetry.hpp"

namespace tensegrity::hil {
namespace {

std::vector<std::string> cells_of(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::stringstream cells(line);
  while (std::getline(cells, cell, ',')) out.push_back(cell);
  return out;
}

std::vector<std::string> lines_of(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

std::filesystem::path temp_csv(const std::string& name) {
  return std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()) + ".csv");
}

TEST(HilRecorder, WritesTheSimulatorsRunRecordSchema) {
  const sim::Robot robot = sim::load_robot(sim::robot_path_named("superball"));
  const sim::Model model(robot, robot.time_step_s);
  const auto hil_path = temp_csv("hil_recorder_test");
  const auto sim_path = temp_csv("hil_recorder_test_sim");
  {
    Recorder recorder(hil_path, model);
    recorder.record(0.0, model);
    recorder.close();
    sim::CsvTelemetry telemetry(sim_path.string());
    telemetry.begin(model);
    telemetry.record(0.0, model);
    telemetry.end();
  }
  const auto hil = lines_of(hil_path);
  const auto sim_lines = lines_of(sim_path);
  std::filesystem::remove(hil_path);
  std::filesystem::remove(sim_path);
  ASSERT_EQ(hil.size(), 2U);
  EXPECT_EQ(hil, sim_lines);
  const auto header = cells_of(hil[0]);
  ASSERT_EQ(header.size(), 1U + 3U + 12U * 3U + 24U * 4U + 3U);
  EXPECT_EQ(header[1], "centre_x_m");
  EXPECT_EQ(header[4], "node0_x_m");
  EXPECT_EQ(header[40 + 3], "cable3_rest_length_m");
  EXPECT_EQ(header[40 + 2 * 24 + 3], "cable3_tension_n");
  EXPECT_EQ(header.back(), "elastic_energy_j");
  EXPECT_EQ(sim::legacy_cable_column(3, "tension_n"), "tension_n_3");
}

TEST(HilRecorder, ARowHoldsEveryColumnAndTheCentreIsTheEndCapsMean) {
  const sim::Robot robot = sim::load_robot(sim::robot_path_named("superball"));
  const sim::Model model(robot, robot.time_step_s);
  const auto path = temp_csv("hil_recorder_row");
  {
    Recorder recorder(path, model);
    recorder.record(1.25, model);
    recorder.close();
  }
  const auto lines = lines_of(path);
  std::filesystem::remove(path);
  ASSERT_EQ(lines.size(), 2U);
  const auto header = cells_of(lines[0]);
  const auto row = cells_of(lines[1]);
  ASSERT_EQ(row.size(), header.size());
  EXPECT_EQ(std::stod(row[0]), 1.25);
  for (int k = 0; k < 3; ++k) {
    double sum = 0.0;
    for (int i = 0; i < 12; ++i) sum += std::stod(row[4 + 3 * i + k]);
    EXPECT_NEAR(std::stod(row[1 + k]), sum / 12.0, 1e-8) << header[1 + k];
    EXPECT_NEAR(std::stod(row[1 + k]), model.centre_m()[k], 1e-8) << header[1 + k];
  }
}

TEST(HilRecorder, AFullDiskIsAnErrorNamingTheFile) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const sim::Robot robot = sim::load_robot(sim::robot_path_named("superball"));
  const sim::Model model(robot, robot.time_step_s);
  Recorder recorder("/dev/full", model);
  for (int i = 0; i < 100; ++i) recorder.record(i * 0.001, model);
  try {
    recorder.close();
    FAIL() << "a record on a full disk closed without an error";
  } catch (const HilError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/full"), std::string::npos) << e.what();
  }
}

TEST(HilRecorder, AFileThatCannotBeCreatedIsAnErrorNamingIt) {
  const sim::Robot robot = sim::load_robot(sim::robot_path_named("superball"));
  const sim::Model model(robot, robot.time_step_s);
  EXPECT_THROW(Recorder("/nonexistent-dir/run.csv", model), HilError);
}

}  // namespace
}  // namespace tensegrity::hil
