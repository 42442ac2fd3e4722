// SPDX-License-Identifier: Apache-2.0
#pragma once
// Where the robot is and how it stands, from what a SUPERball offers the ground: each
// end cap's accelerometer (face_geometry.hpp) and an external position fix of the end
// caps' centre (a GNSS or motion-capture stand-in, about 1-2 Hz, about 0.1 m noise).
//
// - Face: the accelerometers' down direction, nearest hull face, counted once it has
//   held for face_hold_s (a robot in mid-roll says nothing stable).
// - Yaw of the start frame (the frame a gait set's headings are in): nothing on the
//   robot measures it. The estimator follows the robot's whole attitude from a given
//   start, turning it at each reading by the shortest rotation that brings the newly
//   measured down direction down (a robot that tips and rolls without twisting about
//   the vertical); the steering corrects it from the measured path (correct_yaw).
// - Position and velocity: a straight-line fit to the fixes of the last fix_window_s.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <deque>
#include <optional>
#include <span>
#include <vector>

#include "ground/drive/face_geometry.hpp"

namespace tensegrity::drive {

struct EstimatorConfig {
  double face_hold_s = 0.3;
  // Readings are averaged over this long: a rolling robot's end caps accelerate by
  // several m/s^2 as it tips and lands, but over half a second that mostly cancels.
  double average_s = 0.5;
  double fix_window_s = 3.0;
  double initial_yaw_rad = 0.0;
};

struct Estimate {
  bool located = false;  // at least one fix so far
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d velocity_m_per_s = Eigen::Vector2d::Zero();
  int face = -1;  // index into FaceGeometry::faces(); -1 until the accelerometers agree
  double yaw_rad = 0.0;
};

class Estimator {
 public:
  Estimator(const FaceGeometry& geometry, const EstimatorConfig& config);

  // One reading per end cap, in end cap order, taken at time_s (seconds, increasing).
  void add_accelerations(double time_s, std::span<const Eigen::Vector3d> readings_m_per_s2);
  // A position fix of the end caps' centre, world frame, metres.
  void add_fix(double time_s, const Eigen::Vector2d& position_m);
  // The estimate as of time_s (position extrapolated along the fitted line).
  Estimate estimate(double time_s) const;
  // Turns the yaw estimate by `rad` (the steering's measured correction).
  void correct_yaw(double rad);
  int face_changes() const { return face_changes_; }

 private:
  const FaceGeometry& geometry_;
  EstimatorConfig config_;
  int face_ = -1;
  int candidate_ = -1;
  double candidate_since_s_ = 0.0;
  double initial_yaw_rad_;
  struct Reading {
    double time_s;
    std::vector<Eigen::Vector3d> m_per_s2;
  };
  std::deque<Reading> readings_;  // the last average_s
  bool started_ = false;
  Eigen::Matrix3d attitude_ = Eigen::Matrix3d::Identity();  // description -> world
  int face_changes_ = 0;
  struct Fix {
    double time_s;
    Eigen::Vector2d position_m;
  };
  std::deque<Fix> fixes_;
};

}  // namespace tensegrity::drive
