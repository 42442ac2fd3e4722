// SPDX-License-Identifier: Apache-2.0
// `run_robustness` on a short episode: a case that changes nothing keeps the nominal
// distance to the bit, a changed robot does not, the worst case is the least kept, a
// slope case reports its progress up the slope; and the faulty controller's load-cell
// noise and actuation delay do what they say.
#include "sim/analysis/robustness.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <vector>

#include "sim/analysis/faulty_controller.hpp"

namespace tensegrity::sim {
namespace {

using nlohmann::json;

TEST(Robustness, ShortEpisodeAcrossASmallSet) {
  const Robot robot = load_robot(robot_path_named("superball-paper"));
  const Policy policy = load_policy(std::string(TENSEGRITY_SOURCE_DIR) + "/policies/superball-paper-t4-n5.json", robot);
  const json doc = {{"format", kPerturbationSetFormat},
                    {"cases", json::array({{{"name", "unchanged"}},
                                           {{"name", "slow motors"}, {"motor_speed_scale", 0.5}},
                                           {{"name", "uphill"}, {"slope_deg", 10.0}},
                                           {{"name", "noise"}, {"load_cell_noise_n", 5.0}, {"load_cell_seed", 3}}})}};
  const PerturbationSet set = parse_perturbation_set(doc.dump());
  const RobustnessReport report = run_robustness(robot, policy, set, RobustnessOptions{6.0, 2});
  ASSERT_TRUE(report.nominal.feasible);
  ASSERT_GT(report.nominal.distance_m, 0.5);
  ASSERT_EQ(report.cases.size(), 4U);
  for (const auto& c : report.cases) EXPECT_TRUE(c.error.empty()) << c.name << ": " << c.error;
  EXPECT_EQ(report.cases[0].episode.distance_m, report.nominal.distance_m);
  EXPECT_EQ(report.cases[0].retention, 1.0);
  EXPECT_NE(report.cases[1].episode.distance_m, report.nominal.distance_m);
  ASSERT_TRUE(report.cases[2].uphill_m.has_value());
  EXPECT_FALSE(report.cases[0].uphill_m.has_value());
  // Less than its distance: uphill is the projection of where it went.
  EXPECT_LE(*report.cases[2].uphill_m, report.cases[2].episode.distance_m + 1e-12);
  // Uphill is the way it rolls nominally: its retention is its progress up the slope.
  EXPECT_NEAR(report.cases[2].retention * report.nominal.distance_m, *report.cases[2].uphill_m, 1e-9);
  for (const auto& c : report.cases) EXPECT_GE(c.retention, report.cases[report.worst].retention) << c.name;
  // Played again in one thread, every case is the same to the bit.
  const RobustnessReport again = run_robustness(robot, policy, set, RobustnessOptions{6.0, 1});
  for (std::size_t i = 0; i < report.cases.size(); ++i) {
    EXPECT_EQ(again.cases[i].episode.distance_m, report.cases[i].episode.distance_m) << report.cases[i].name;
  }
}

// Remembers what it was given and commands its step number to every cable.
class Recorder final : public Controller {
 public:
  void reset(const Robot&) override { seen.clear(); }
  void update(const ControlInput& input, std::span<double> preferred) override {
    seen.emplace_back(input.tension_n.begin(), input.tension_n.end());
    for (double& p : preferred) p = static_cast<double>(input.step);
  }
  std::vector<std::vector<double>> seen;
};

TEST(FaultyController, DelaysCommandsAndDisturbsTheLoadCells) {
  Recorder inner;
  FaultyController faulty(inner, HardwareFaults{2.0, 10.0, 5, 0.003});
  const Robot robot = load_robot(robot_path_named("superball-paper"));
  faulty.reset(robot);
  const std::vector<double> tension(3, 100.0);
  const std::vector<double> rest(3, 0.85);
  std::vector<double> out(3);
  double sum = 0.0;
  const int steps = 2000;
  for (int k = 0; k < steps; ++k) {
    faulty.update(ControlInput{k, k * 0.001, 0.001, tension, rest}, out);
    // Three steps late; until then the motors hold the lengths they had.
    EXPECT_EQ(out[0], k < 3 ? 0.85 : static_cast<double>(k - 3)) << "step " << k;
    sum += inner.seen.back()[1];
  }
  const double mean = sum / steps;
  EXPECT_NEAR(mean, 110.0, 0.3) << "the bias is 10 N, the noise averages out";
  EXPECT_NE(inner.seen[0][0], inner.seen[0][1]) << "each cable gets its own noise";
  Recorder clean;
  FaultyController none(clean, HardwareFaults{});
  none.reset(robot);
  none.update(ControlInput{0, 0.0, 0.001, tension, rest}, out);
  EXPECT_EQ(clean.seen[0], tension);
  EXPECT_EQ(out[0], 0.0) << "no delay: the command passes at once";
}

}  // namespace
}  // namespace tensegrity::sim
