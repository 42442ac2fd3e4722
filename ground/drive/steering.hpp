// SPDX-License-Identifier: Apache-2.0
#pragma once
// Which gait to play next, chosen at each period boundary (the end caps swap tables
// only there) to head for the active waypoint of a course.
//
// The gait being played is kept while the heading its measured path shows points
// within keep_within_deg of the waypoint, and always for its first hold_periods (a
// gait switched in mid-roll has a transient). Otherwise the candidates are it and the
// gait set's gaits for the face the robot stands on, whose world heading is their
// heading in that face's start frame plus the estimated yaw. The one whose heading
// points nearest the waypoint wins; a switch must gain switch_margin_deg. A heading
// between the gaits' is reached by alternating them as the bearing swings past. After each period the path a freshly
// chosen gait rolled is compared with what was expected of it and the yaw estimate
// turned by yaw_gain of the difference: the model's ground is not isotropic, so a
// gait's heading carried by symmetry is off by up to about 25 degrees, and the yaw
// followed from face to face drifts.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "ground/drive/estimator.hpp"
#include "robot/gait_set.hpp"

namespace tensegrity::drive {

struct SteeringConfig {
  double within_m = 1.5;  // a waypoint is reached this near
  double switch_margin_deg = 10.0;
  double min_segment_m = 1.0;
  double yaw_gain = 0.5;
  // A gait just switched in rolls a transient first: it plays at least hold_periods,
  // and its heading is measured from the end of its first period.
  int hold_periods = 2;
  // The gait being played is kept while its measured heading is this near the bearing.
  double keep_within_deg = 50.0;
};

struct Choice {
  int gait = -1;  // index into the set's gaits
  bool switched = false;
  double expected_heading_rad = 0.0;  // world
  double bearing_rad = 0.0;           // world, toward the waypoint
};

class Steering {
 public:
  Steering(const sim::GaitSet& set, const FaceGeometry& geometry, std::vector<Eigen::Vector2d> waypoints_m,
           const SteeringConfig& config);

  // At a period boundary (or the start): corrects the estimator's yaw by the path
  // since the last switch, then chooses. No gait until the estimate has a face and a
  // fix (then: -1).
  Choice choose(double time_s, Estimator& estimator);
  // Between boundaries: advances to the next waypoint when the estimate is within
  // within_m of it, or has passed its closest approach inside within_m.
  void update(const Estimate& estimate);

  bool done() const { return active_ >= waypoints_.size(); }
  std::size_t active() const { return active_; }
  const std::vector<Eigen::Vector2d>& waypoints() const { return waypoints_; }
  // The gaits of the set that start from each face (index into the faces).
  const std::vector<std::vector<int>>& gaits_by_face() const { return by_face_; }

 private:
  // The heading the current gait has shown since it was chosen, when it has gone far enough.
  std::optional<double> measured_heading(const Estimate& now) const;
  void correct_yaw(const Estimate& now, Estimator& estimator);
  struct Candidate {
    int gait;
    double error_rad;    // from the bearing
    double heading_rad;  // world, expected
  };
  // The gait of the set for the estimate's face that points nearest `bearing_rad`.
  Candidate best_candidate(const Estimate& now, double bearing_rad) const;

  const sim::GaitSet& set_;
  std::vector<Eigen::Vector2d> waypoints_;
  SteeringConfig config_;
  std::vector<std::vector<int>> by_face_;
  std::vector<double> heading_rad_;  // per gait, in its face's start frame
  std::size_t active_ = 0;
  double best_distance_m_ = 1e300;
  // The segment since the last switch: the gait, where and what it was expected to do.
  int gait_ = -1;
  int periods_ = 0;  // boundaries since the switch
  Eigen::Vector2d segment_start_m_ = Eigen::Vector2d::Zero();
  double segment_expected_rad_ = 0.0;
  double segment_corrected_rad_ = 0.0;  // yaw correction already applied for this segment
};

// Radians in (-pi, pi].
double wrap_rad(double rad);

}  // namespace tensegrity::drive
