// SPDX-License-Identifier: Apache-2.0
// `hil --record` and `sim --telemetry` write one run-record scheme: every column the
// HIL names is named the same in the simulator's record (the HIL adds only the
// centre), so the view and tools/ read both by the same names.
#include "hil/recorder.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "robot/robot.hpp"
#include "sim/model/telemetry.hpp"

namespace tensegrity::hil {
namespace {

std::vector<std::string> header_of(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line, cell;
  std::getline(in, line);
  std::vector<std::string> out;
  std::stringstream cells(line);
  while (std::getline(cells, cell, ',')) out.push_back(cell);
  return out;
}

TEST(HilRecorder, NamesEveryColumnAsTheSimulatorsRecordDoes) {
  const sim::Robot robot = sim::load_robot(sim::robot_path_named("superball"));
  const sim::Model model(robot, robot.time_step_s);
  const auto dir = std::filesystem::temp_directory_path();
  const auto hil_path = dir / ("hil_recorder_test_" + std::to_string(::getpid()) + ".csv");
  const auto sim_path = dir / ("hil_recorder_test_sim_" + std::to_string(::getpid()) + ".csv");
  {
    Recorder recorder(hil_path, model);
    recorder.record(0.0, model);
    recorder.close();
    sim::CsvTelemetry telemetry(sim_path.string());
    telemetry.begin(model);
    telemetry.end();
  }
  const auto hil = header_of(hil_path);
  const auto sim_header = header_of(sim_path);
  std::filesystem::remove(hil_path);
  std::filesystem::remove(sim_path);
  const std::set<std::string> sim_names(sim_header.begin(), sim_header.end());
  ASSERT_EQ(hil.size(), 4U + 24U * 2U + 12U * 3U + 3U);
  for (const auto& name : hil) {
    if (name.rfind("centre_", 0) == 0) continue;
    EXPECT_TRUE(sim_names.count(name)) << name << " is not a column of `sim --telemetry`";
  }
  EXPECT_EQ(hil[4 + 3], "cable3_rest_length_m");
  EXPECT_EQ(hil[4 + 24 + 3], "cable3_tension_n");
  EXPECT_EQ(sim::cable_column(3, "tension_n"), "cable3_tension_n");
  EXPECT_EQ(sim::legacy_cable_column(3, "tension_n"), "tension_n_3");
}

}  // namespace
}  // namespace tensegrity::hil
