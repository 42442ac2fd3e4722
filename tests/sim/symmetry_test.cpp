// SPDX-License-Identifier: Apache-2.0
// The robot's symmetry group, the image of a gait under a symmetry, and the physics
// agreeing: a mirrored gait, played from the mirrored start, rolls the mirrored path.
#include "robot/symmetry.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>

#include "sim/model/core_controller.hpp"
#include "sim/model/episode.hpp"

namespace tensegrity::sim {
namespace {

namespace fs = std::filesystem;

Robot paper() { return load_robot(default_robot_path()); }
fs::path shipped() {
  return default_robot_path().parent_path().parent_path() / "policies" / "superball-paper-t4-n5.json";
}

// The end-cap map of `a` after `b`.
std::vector<int> compose(const Symmetry& a, const Symmetry& b) {
  std::vector<int> out(b.node_map.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = a.node_map[b.node_map[i]];
  return out;
}

// The pose `nodes`, mirrored by `world` (a horizontal isometry about the centre) and
// relabelled by `s`, placed at rest: end cap node_map[i] where world puts end cap i.
ModelState mirrored_start(const Robot& robot, const std::vector<Eigen::Vector3d>& nodes, const Symmetry& s,
                          const Eigen::Matrix3d& world) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : nodes) c += p / static_cast<double>(nodes.size());
  std::vector<Eigen::Vector3d> image(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i) image[s.node_map[i]] = c + world * (nodes[i] - c);
  Model model(robot, robot.time_step_s);
  model.place(image);
  return model.save();
}

std::vector<Eigen::Vector3d> settled_nodes(const Robot& robot) {
  Model model(robot, robot.time_step_s);
  model.restore(settled_state(robot, robot.time_step_s));
  return model.node_positions();
}

Eigen::Vector2d roll(const Robot& robot, const Policy& policy, const ModelState& start, double duration_s) {
  CoreController controller(robot, policy);
  EpisodeOptions options;
  options.duration_s = duration_s;
  options.start_state = &start;
  const EpisodeResult r = run_episode(robot, controller, options);
  EXPECT_TRUE(r.feasible) << r.infeasible_reason;
  return r.displacement_m;
}

TEST(SymmetryGroup, TheIcosahedronHasTwentyFourClosedUnderComposition) {
  const Robot robot = paper();
  const auto group = symmetry_group(robot);
  ASSERT_EQ(group.size(), 24u);  // the pyritohedral group: 3-fold turns, axis flips, inversion
  EXPECT_TRUE(group.front().matrix.isIdentity(1e-12));
  std::set<std::vector<int>> maps;
  for (const Symmetry& s : group) maps.insert(s.node_map);
  EXPECT_EQ(maps.size(), group.size());
  for (const Symmetry& a : group) {
    for (const Symmetry& b : group) EXPECT_TRUE(maps.contains(compose(a, b))) << a.name << " after " << b.name;
    // Each cable's image joins the images of its end caps.
    for (int m = 0; m < robot.cable_count(); ++m) {
      const auto& from = robot.cables[m];
      const auto& to = robot.cables[a.cable_map[m]];
      const std::set<int> want{a.node_map[from.node_a], a.node_map[from.node_b]};
      EXPECT_EQ((std::set<int>{to.node_a, to.node_b}), want);
    }
  }
}

TEST(SymmetryGroup, OnlyWhatTheRobotFileAllows) {
  Robot cut = paper();
  cut.cables.erase(cut.cables.begin());  // a cable fewer: only maps that fix that pair's absence survive
  const auto fewer = symmetry_group(cut);
  EXPECT_LT(fewer.size(), 24u);
  EXPECT_GE(fewer.size(), 1u);
  Robot stiff = paper();
  stiff.cables[3].stiffness_n_per_m *= 2.0;  // a cable unlike the others
  EXPECT_LT(symmetry_group(stiff).size(), 24u);
  Robot bent = paper();
  bent.nodes_m[5].x() += 0.01;  // the geometry no longer symmetric
  const auto alone = symmetry_group(bent);
  ASSERT_EQ(alone.size(), 1u);
  EXPECT_TRUE(alone.front().matrix.isIdentity(1e-12));
}

TEST(SymmetryGroup, ImageMovesEachTableToTheImageCable) {
  const Robot robot = paper();
  const Policy policy = load_policy(shipped(), robot);
  const auto group = symmetry_group(robot);
  const Symmetry& mirror = find_symmetry(group, "(-x,y,z)");
  const Policy image = image_of(policy, mirror, robot);
  for (int m = 0; m < robot.cable_count(); ++m) {
    const int to = mirror.cable_map[m];
    EXPECT_EQ(image.cables[to].rest_lengths_m, policy.cables[m].rest_lengths_m);
    EXPECT_EQ(image.cables[to].owner, robot.cables[to].owner);
  }
  EXPECT_EQ(image.provenance.symmetry, "(-x, y, z)");
  EXPECT_FALSE(image.provenance.heading_deg.has_value());
  // A mirror is its own inverse: twice gives the policy back, and it still parses.
  const Policy twice = image_of(image, mirror, robot);
  for (int m = 0; m < robot.cable_count(); ++m)
    EXPECT_EQ(twice.cables[m].rest_lengths_m, policy.cables[m].rest_lengths_m);
  EXPECT_NO_THROW(parse_policy(policy_to_json(image), robot));
  EXPECT_THROW(find_symmetry(group, "(y, x, z)"), PolicyError);
  EXPECT_NO_THROW(find_symmetry(group, "identity"));
}

TEST(SymmetryGroup, TheSettledFaceIsKeptByTheIdentityAndTwoThirdTurns) {
  const Robot robot = paper();
  const auto group = symmetry_group(robot);
  const auto faces = hull_faces(robot);
  ASSERT_EQ(faces.size(), 20u);
  EXPECT_EQ(std::count_if(faces.begin(), faces.end(), [](const HullFace& f) { return f.closed; }), 8);
  const StartFrame frame = start_frame(robot, faces, settled_nodes(robot));
  ASSERT_GE(frame.face, 0);
  std::vector<double> turns_deg;
  for (const Symmetry& s : group) {
    if (face_image(s, faces, frame.face) != frame.face) continue;
    EXPECT_TRUE(s.proper()) << s.name;
    const Eigen::Matrix2d a = heading_map(s, faces, frame.face);
    turns_deg.push_back(std::round(std::atan2(a(1, 0), a(0, 0)) * 180.0 / M_PI));
  }
  std::sort(turns_deg.begin(), turns_deg.end());
  EXPECT_EQ(turns_deg, (std::vector<double>{-120.0, 0.0, 120.0}));
  // Every closed face is some symmetry's image of the settled one, three times over.
  std::vector<int> hits(faces.size(), 0);
  for (const Symmetry& s : group) ++hits[face_image(s, faces, frame.face)];
  for (std::size_t f = 0; f < faces.size(); ++f) EXPECT_EQ(hits[f], faces[f].closed ? 3 : 0);
}

// The model cannot tell a pose from its mirror image: every reflection's image of the
// shipped gait, played from the settled pose mirrored in the world's xz plane and
// relabelled, rolls the mirror image of the gait's own path. The tolerance is what
// floating-point rounding alone makes of the same physics over the same time: the
// gait from the settled pose turned a quarter about the vertical (the ground's
// friction pyramid has its axes along x and y, so a quarter turn maps it onto itself)
// against the quarter-turned path.
TEST(SymmetryPhysics, MirroredGaitRollsTheMirroredPath) {
  const Robot robot = paper();
  const Policy policy = load_policy(shipped(), robot);
  const auto group = symmetry_group(robot);
  const auto nodes = settled_nodes(robot);
  const Symmetry& id = group.front();
  const double duration_s = 20.0;  // five periods
  const Eigen::Vector2d d =
      roll(robot, policy, mirrored_start(robot, nodes, id, Eigen::Matrix3d::Identity()), duration_s);
  ASSERT_GT(d.norm(), 5.0);
  const Eigen::Matrix3d quarter = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector2d dq = roll(robot, policy, mirrored_start(robot, nodes, id, quarter), duration_s);
  const double tolerance_m = std::max((dq - quarter.topLeftCorner<2, 2>() * d).norm(), 1e-9);
  RecordProperty("tolerance_m", std::to_string(tolerance_m));
  RecordProperty("distance_m", std::to_string(d.norm()));
  EXPECT_LT(tolerance_m, 0.05 * d.norm()) << "rounding alone moves the path this much: no test";
  const Eigen::Matrix3d flip_y = Eigen::Vector3d(1, -1, 1).asDiagonal();
  const Eigen::Vector2d want(d.x(), -d.y());
  int reflections = 0;
  for (const Symmetry& s : group) {
    if (s.proper()) continue;
    ++reflections;
    const Eigen::Vector2d got =
        roll(robot, image_of(policy, s, robot), mirrored_start(robot, nodes, s, flip_y), duration_s);
    EXPECT_LE((got - want).norm(), tolerance_m) << s.name;
  }
  EXPECT_EQ(reflections, 12);
  // The test can fail: one reflection's gait from another's start does not roll there.
  const Symmetry& a = find_symmetry(group, "(-x,y,z)");
  const Symmetry& b = find_symmetry(group, "(x,-y,z)");
  const Eigen::Vector2d wrong =
      roll(robot, image_of(policy, a, robot), mirrored_start(robot, nodes, b, flip_y), duration_s);
  EXPECT_GT((wrong - want).norm(), 100.0 * tolerance_m);
}

}  // namespace
}  // namespace tensegrity::sim
