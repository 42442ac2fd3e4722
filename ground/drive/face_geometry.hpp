// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the end caps' accelerometers say about the robot's pose: the direction that
// points down and the hull face it stands on. Only the rest
// geometry of the robot file is used: no physics, so the same code serves the
// in-process model, the HIL and a robot.
//
// An end cap's accelerometer reads the specific force in the end cap's own frame,
// whose z axis lies along its strut, pointing out of the end cap (away from the
// strut's middle); its x and y axes turn with the strut about that axis. Only the z
// reading is used here: how far a strut spins about its own axis is unknown to the
// ground, but the angle between the strut and gravity is not.
#include <Eigen/Core>
#include <optional>
#include <span>
#include <vector>

#include "robot/robot.hpp"
#include "robot/start_frame.hpp"

namespace tensegrity::drive {

inline constexpr double kGravity_m_per_s2 = 9.81;

class FaceGeometry {
 public:
  explicit FaceGeometry(const sim::Robot& robot);

  const std::vector<sim::HullFace>& faces() const { return faces_; }
  int endcap_count() const { return static_cast<int>(axis_.size()); }
  // The index of the face with these end caps (any order), or -1.
  int face_index(std::array<int, 3> nodes) const;

  // The direction that points down, in the description frame, fitted (least squares)
  // to each end cap's axial reading: a reading of +g along an axis means the axis
  // points straight up. None when the readings are too weak to say (free fall).
  std::optional<Eigen::Vector3d> down(std::span<const Eigen::Vector3d> readings_m_per_s2) const;
  // The face whose outward normal is nearest `down` (description frame).
  int nearest_face(const Eigen::Vector3d& down) const;

 private:
  std::vector<sim::HullFace> faces_;
  std::vector<Eigen::Vector3d> axis_;             // per end cap: outward along its strut, description frame
  Eigen::Matrix<double, 3, Eigen::Dynamic> fit_;  // least-squares solution for `down`
};

}  // namespace tensegrity::drive
