// SPDX-License-Identifier: Apache-2.0
// The whole analysis on a short real episode: a seeded random policy on the default
// robot, recorded at 100 Hz, analysed, written.
#include "sim/analysis/analysis.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <cmath>
#include <random>

#include "sim/analysis/csv_files.hpp"
#include "sim/model/core_controller.hpp"
#include "sim/model/episode.hpp"
#include "robot/policy.hpp"

namespace tensegrity::sim::analysis {
namespace {

Policy random_policy(const Robot& robot, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> rest(robot.motor.min_rest_length_m, robot.motor.max_rest_length_m);
  Policy p;
  p.robot = robot.name;
  p.period_s = 2.0;
  p.complexity = 4;
  for (int c = 0; c < robot.cable_count(); ++c) {
    CablePolicy cable{c, robot.cables[static_cast<std::size_t>(c)].owner, {}};
    for (int i = 0; i < p.complexity; ++i) cable.rest_lengths_m.push_back(rest(rng));
    p.cables.push_back(cable);
  }
  return p;
}

std::size_t lines_in(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) ++n;
  return n;
}

TEST(Analysis, AShortEpisodeGivesEveryFigureAndWritesItsFiles) {
  const Robot robot = load_robot(robot_path_named("superball"));
  const Policy policy = random_policy(robot, 3);
  CoreController controller(robot, policy);
  EpisodeSeries series;
  SeriesRecorder recorder(series);
  EpisodeOptions options;
  options.duration_s = 5.0;
  options.telemetry = &recorder;
  options.telemetry_every = static_cast<int>(std::lround(0.01 / robot.time_step_s));
  const EpisodeResult result = run_episode(robot, controller, options);
  ASSERT_TRUE(result.feasible) << result.infeasible_reason;
  ASSERT_EQ(series.samples(), 501u);

  std::vector<std::pair<int, int>> cable_nodes;
  for (const auto& c : robot.cables) cable_nodes.emplace_back(c.node_a, c.node_b);
  AnalysisOptions o;
  o.period_s = policy.period_s;
  const Analysis a = analyze(series, cable_nodes, o);
  EXPECT_NEAR(a.window_start_s, 2.0, 1e-9);  // the first period left out
  ASSERT_EQ(a.muscles.size(), robot.cables.size());
  for (const auto& m : a.muscles) {
    EXPECT_GE(m.rest_min_m, robot.motor.min_rest_length_m - 1e-9);
    EXPECT_LE(m.rest_max_m, robot.motor.max_rest_length_m + 1e-9);
    EXPECT_LE(m.rest_min_m, m.rest_mean_m);
    EXPECT_LE(m.rest_mean_m, m.rest_max_m);
    EXPECT_GE(m.length_mean_m, m.rest_mean_m - 0.01);  // cables only pull: stretched, or slack
  }
  for (std::size_t i = 0; i < a.correlation.size(); ++i) EXPECT_NEAR(a.correlation[i][i], 1.0, 1e-12);
  EXPECT_EQ(a.tree.merges.size(), robot.cables.size() - 1);
  EXPECT_EQ(a.aligned_tree.leaf_order.size(), robot.cables.size());
  // It starts on a face: at least three end caps touch.
  EXPECT_GE(a.contacts.touched_count(), 3);
  ASSERT_FALSE(a.faces.empty());
  EXPECT_TRUE(a.faces.front().closed);

  const auto dir = std::filesystem::path(::testing::TempDir()) / "analysis_test";
  std::filesystem::remove_all(dir);
  const auto files = write_csv_files(dir, series, a);
  EXPECT_EQ(files.size(), 12u);
  for (const auto& f : files) EXPECT_GT(std::filesystem::file_size(dir / f), 10u) << f;
  EXPECT_EQ(lines_in(dir / "fig10_11_muscles.csv"), robot.cables.size() + 1);
  EXPECT_EQ(lines_in(dir / "fig11_timeseries.csv"), series.samples() + 1);
  EXPECT_EQ(lines_in(dir / "fig12_linkage.csv"), robot.cables.size());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace tensegrity::sim::analysis
