// SPDX-License-Identifier: Apache-2.0
#pragma once
// Where the robot went, in the world and in its start frame. The start frame is the
// robot's own: it stands on one face of its rest geometry's hull, and the frame is
// the world turned about the vertical so that the robot lies in that face's
// canonical face-down pose (the description turned by the shortest rotation that
// points the face straight down, as the settled start does). From the settled start
// the start frame is the world frame; from any other pose it is the one in which a
// gait's heading is what it was from the settled start of that face.
#include <Eigen/Core>
#include <array>
#include <optional>
#include <span>
#include <vector>

#include "robot/robot.hpp"

namespace tensegrity::sim {

// A triangle of the convex hull of the description's end caps.
struct HullFace {
  std::array<int, 3> nodes{};                        // increasing
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // outward, unit, description frame
  bool closed = false;                               // all three edges are cables
};

// Every hull face whose three end caps have no other end cap in their plane (a
// description with four coplanar end caps on its hull has no face there).
std::vector<HullFace> hull_faces(const Robot& robot);

// The rotation that turns the description so `outward_normal` points straight down:
// the shortest one, as the settled start turns its face down.
Eigen::Matrix3d face_down_turn(const Eigen::Vector3d& outward_normal);

// The proper rotation that best maps the centred `from` onto the centred `to`
// (least squares, Kabsch).
Eigen::Matrix3d fit_rotation(std::span<const Eigen::Vector3d> from, std::span<const Eigen::Vector3d> to);

struct StartFrame {
  Eigen::Vector2d origin_m = Eigen::Vector2d::Zero();  // the end caps' horizontal centre
  double yaw_rad = 0.0;                                // the frame's x axis, from the world's x, counter-clockwise
  int face = -1;                                       // index into hull_faces(robot); -1 when there are none
  Eigen::Matrix3d body = Eigen::Matrix3d::Identity();  // description -> world rotation that best fits the pose
};

// The start frame of the pose `nodes_m` (world, one per end cap): the hull face
// pointing most nearly down is the one the robot stands on.
StartFrame start_frame(const Robot& robot, const std::vector<HullFace>& faces,
                       std::span<const Eigen::Vector3d> nodes_m);

struct Travel {
  Eigen::Vector2d world_m = Eigen::Vector2d::Zero();  // end centre minus start centre, world frame
  Eigen::Vector2d start_m = Eigen::Vector2d::Zero();  // the same in the start frame
  double distance_m = 0.0;
  // atan2 of start_m, degrees in (-180, 180]: none when the robot did not move.
  std::optional<double> heading_deg;
  double yaw_deg = 0.0;  // the start frame's yaw (world heading = heading_deg + yaw_deg)
};

Travel travel(const StartFrame& frame, const Eigen::Vector2d& end_centre_m);

// Degrees in (-180, 180].
double wrap_deg(double deg);

}  // namespace tensegrity::sim
