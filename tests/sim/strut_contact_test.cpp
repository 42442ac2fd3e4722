// SPDX-License-Identifier: Apache-2.0
// Strut contact: the bound that spares most pairs of struts the exact closest-approach
// test must never change what the exact test of every pair gives.
#include <ode/ode.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "sim/model/core_controller.hpp"
#include "sim/model/episode.hpp"
#include "sim/model/model.hpp"
#include "robot/policy.hpp"

namespace tensegrity::sim {
namespace {

struct AllPairs {
  double min_gap_m = std::numeric_limits<double>::infinity();
  int overlaps = 0;
};

// Every pair measured exactly, as the model did before it culled any.
AllPairs measure_all_pairs(const Robot& robot, const std::vector<Eigen::Vector3d>& nodes) {
  auto to_ode = [](const Eigen::Vector3d& p, dVector3 out) {
    for (int k = 0; k < 3; ++k) out[k] = p[k];
    out[3] = 0.0;
  };
  const double r = robot.strut_radius_m;
  AllPairs all;
  for (std::size_t i = 0; i < robot.struts.size(); ++i) {
    for (std::size_t j = i + 1; j < robot.struts.size(); ++j) {
      dVector3 a1, a2, b1, b2, on_a, on_b;
      to_ode(nodes[robot.struts[i].node_a], a1);
      to_ode(nodes[robot.struts[i].node_b], a2);
      to_ode(nodes[robot.struts[j].node_a], b1);
      to_ode(nodes[robot.struts[j].node_b], b2);
      dClosestLineSegmentPoints(a1, a2, b1, b2, on_a, on_b);
      const Eigen::Vector3d pa(on_a[0], on_a[1], on_a[2]);
      const Eigen::Vector3d pb(on_b[0], on_b[1], on_b[2]);
      const double distance = (pa - pb).norm();
      all.min_gap_m = std::min(all.min_gap_m, distance - 2.0 * r);
      if (distance < 2.0 * r && distance >= 1e-9) ++all.overlaps;
    }
  }
  return all;
}

TEST(StrutContact, CullingPairsKeepsEveryOverlapAndTheSmallestGapToTheBit) {
  // The default robot's gait: its struts touch and overlap for seconds at a time.
  const Robot robot = load_robot(default_robot_path());
  ASSERT_TRUE(robot.rod_contact);
  const auto policy_path = default_robot_path().parent_path().parent_path() / "policies" / "superball-paper-t4-n5.json";
  CoreController controller(robot, load_policy(policy_path, robot));
  controller.reset(robot);
  Model model(robot, robot.time_step_s);
  model.restore(settled_state(robot, robot.time_step_s));
  std::vector<double> preferred(model.rest_length_m().begin(), model.rest_length_m().end());
  int steps_with_overlap = 0;
  long measured = 0;
  const int steps = 20000;  // 20 s: two and a half revolutions
  for (int k = 0; k < steps; ++k) {
    ControlInput input;
    input.step = k;
    input.time_s = k * model.dt_s();
    input.dt_s = model.dt_s();
    input.tension_n = model.tension_n();
    input.rest_length_m = model.rest_length_m();
    controller.update(input, preferred);
    // The step measures the struts where they stand before it moves them.
    const AllPairs all = measure_all_pairs(robot, model.node_positions());
    model.step(preferred);
    ASSERT_EQ(model.min_strut_gap_m(), all.min_gap_m) << "step " << k;
    ASSERT_EQ(model.strut_contact_count(), all.overlaps) << "step " << k;
    if (all.overlaps > 0) ++steps_with_overlap;
    measured += model.strut_pairs_measured();
  }
  EXPECT_GT(steps_with_overlap, 100) << "the gait should have made the struts overlap";
  // Without the cull every step measures all 15 pairs exactly.
  EXPECT_LT(static_cast<double>(measured) / steps, 5.0);
}

}  // namespace
}  // namespace tensegrity::sim
