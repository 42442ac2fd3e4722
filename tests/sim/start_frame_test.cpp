// SPDX-License-Identifier: Apache-2.0
// The start frame: a face's canonical face-down pose has yaw 0, the same pose turned
// about the vertical has that turn as its yaw, and travel is read in the frame.
#include "robot/start_frame.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "sim/model/core_controller.hpp"
#include "sim/model/episode.hpp"

namespace tensegrity::sim {
namespace {

std::vector<Eigen::Vector3d> pose(const Robot& robot, const HullFace& face, double yaw_rad, const Eigen::Vector3d& at) {
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix() * face_down_turn(face.normal);
  std::vector<Eigen::Vector3d> nodes;
  for (const auto& p : robot.nodes_m) nodes.push_back(at + r * p);
  return nodes;
}

TEST(StartFrame, EachFaceTurnedAboutTheVerticalGivesItsFaceAndYaw) {
  const Robot robot = load_robot(default_robot_path());
  const auto faces = hull_faces(robot);
  ASSERT_EQ(faces.size(), 20u);
  for (std::size_t f = 0; f < faces.size(); ++f) {
    for (double yaw_deg : {0.0, 37.0, -150.0, 180.0}) {
      const auto nodes = pose(robot, faces[f], yaw_deg * M_PI / 180.0, {3.0, -2.0, 0.8});
      const StartFrame frame = start_frame(robot, faces, nodes);
      EXPECT_EQ(frame.face, static_cast<int>(f));
      EXPECT_NEAR(wrap_deg(frame.yaw_rad * 180.0 / M_PI - yaw_deg), 0.0, 1e-9) << "face " << f;
      EXPECT_NEAR(frame.origin_m.x(), 3.0, 1e-12);
    }
  }
}

TEST(StartFrame, TravelIsReadInTheStartFrame) {
  StartFrame frame;
  frame.origin_m = {1.0, 1.0};
  frame.yaw_rad = M_PI / 2;  // the frame's x axis is the world's y
  const Travel t = travel(frame, {1.0, 3.0});
  EXPECT_NEAR(t.distance_m, 2.0, 1e-12);
  EXPECT_NEAR(t.start_m.x(), 2.0, 1e-12);
  EXPECT_NEAR(t.start_m.y(), 0.0, 1e-12);
  ASSERT_TRUE(t.heading_deg.has_value());
  EXPECT_NEAR(*t.heading_deg, 0.0, 1e-9);
  EXPECT_NEAR(t.yaw_deg, 90.0, 1e-9);
  EXPECT_FALSE(travel(frame, {1.0, 1.0}).heading_deg.has_value());
  EXPECT_EQ(wrap_deg(-180.0), 180.0);
  EXPECT_EQ(wrap_deg(540.0), 180.0);
  EXPECT_NEAR(wrap_deg(-190.0), 170.0, 1e-12);
}

// An episode reports its start face and the heading in its start frame, which from
// a start turned about the vertical is the world heading less the turn.
TEST(StartFrame, EpisodeReportsTheSettledFaceAndHeading) {
  const Robot robot = load_robot(default_robot_path());
  const auto faces = hull_faces(robot);
  const Policy policy =
      load_policy(default_robot_path().parent_path().parent_path() / "policies" / "superball-paper-t4-n5.json", robot);
  CoreController controller(robot, policy);
  EpisodeOptions options;
  options.duration_s = 8.0;
  const EpisodeResult r = run_episode(robot, controller, options);
  ASSERT_EQ(r.start_face.size(), 3u);
  // The settled start stands on a closed cable triangle.
  bool closed = false;
  for (const auto& f : faces)
    closed = closed || (f.closed && std::vector<int>(f.nodes.begin(), f.nodes.end()) == r.start_face);
  EXPECT_TRUE(closed);
  ASSERT_TRUE(r.travel.heading_deg.has_value());
  const double world = std::atan2(r.displacement_m.y(), r.displacement_m.x()) * 180.0 / M_PI;
  EXPECT_NEAR(wrap_deg(*r.travel.heading_deg + r.travel.yaw_deg - world), 0.0, 1e-6);
  EXPECT_NEAR(r.travel.world_m.x(), r.displacement_m.x(), 1e-12);
}

}  // namespace
}  // namespace tensegrity::sim
