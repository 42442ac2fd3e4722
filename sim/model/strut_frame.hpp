// SPDX-License-Identifier: Apache-2.0
#pragma once
// Strut body frames and where cables attach on an end cap's surface (docs/design/model.md,
// "Strut spin about its own axis").
#include <Eigen/Core>
#include <span>

#include "robot/robot.hpp"

namespace tensegrity::sim {

// A strut's body frame (columns x, y, z in world coordinates) that turns with the
// whole pose: z along the strut (node a to node b), x toward the pose's centre. A
// rigidly turned pose gives every strut the same twist about its axis, so points
// fixed on a strut's surface stay where they were put.
Eigen::Matrix3d strut_frame(std::span<const Eigen::Vector3d> nodes_m, int node_a, int node_b);

// Body-frame offset, from end cap `from`'s centre, of where a cable to node `to`
// attaches: on the surface (strut.radius_m off the axis) toward `to` in the
// description's pose, as NTRT relocates cable anchors (tgRodInfo::getConnectionPoint).
Eigen::Vector3d surface_attachment(const Robot& robot, int strut, int from, int to);

}  // namespace tensegrity::sim
