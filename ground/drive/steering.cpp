// SPDX-License-Identifier: Apache-2.0
#include "ground/drive/steering.hpp"

#include <cmath>
#include <numbers>

namespace tensegrity::drive {

namespace {
constexpr double kReachMargin = 0.75;
}  // namespace

double wrap_rad(double rad) {
  double w = std::fmod(rad, 2.0 * std::numbers::pi);
  if (w > std::numbers::pi) w -= 2.0 * std::numbers::pi;
  if (w <= -std::numbers::pi) w += 2.0 * std::numbers::pi;
  return w;
}

Steering::Steering(const sim::GaitSet& set, const FaceGeometry& geometry, std::vector<Eigen::Vector2d> waypoints_m,
                   const SteeringConfig& config)
    : set_(set), waypoints_(std::move(waypoints_m)), config_(config), by_face_(geometry.faces().size()) {
  for (std::size_t g = 0; g < set.gaits.size(); ++g) {
    const int face = geometry.face_index(set.gaits[g].face);
    if (face >= 0) by_face_[face].push_back(static_cast<int>(g));
    heading_rad_.push_back(set.gaits[g].heading_deg * std::numbers::pi / 180.0);
  }
}

std::optional<double> Steering::measured_heading(const Estimate& now) const {
  const Eigen::Vector2d d = now.position_m - segment_start_m_;
  if (gait_ < 0 || d.norm() < config_.min_segment_m) return std::nullopt;
  return std::atan2(d.y(), d.x());
}

void Steering::correct_yaw(const Estimate& now, Estimator& estimator) {
  const auto seen = measured_heading(now);
  if (!seen) return;
  // The whole segment's error, re-measured as it grows; what was applied is taken back.
  const double want = config_.yaw_gain * wrap_rad(*seen - segment_expected_rad_);
  estimator.correct_yaw(want - segment_corrected_rad_);
  segment_corrected_rad_ = want;
}

Choice Steering::choose(double time_s, Estimator& estimator) {
  Estimate now = estimator.estimate(time_s);
  update(now);
  Choice c;
  c.gait = gait_;
  if (done() || !now.located || now.face < 0) return c;
  if (gait_ >= 0) {
    ++periods_;
    // The first period's transient is not the gait's heading: measure from its end.
    if (periods_ == 1) segment_start_m_ = now.position_m;
    if (periods_ >= 2) correct_yaw(now, estimator);
    now = estimator.estimate(time_s);
  }
  const Eigen::Vector2d to = waypoints_[active_] - now.position_m;
  c.bearing_rad = std::atan2(to.y(), to.x());
  // Staying: the way the current gait has gone, else what was expected of it.
  double keep_error = 1e300;
  if (gait_ >= 0) {
    c.expected_heading_rad = measured_heading(now).value_or(segment_expected_rad_);
    keep_error = std::abs(wrap_rad(c.expected_heading_rad - c.bearing_rad));
    if (periods_ < config_.hold_periods || keep_error <= config_.keep_within_deg * std::numbers::pi / 180.0) {
      return c;
    }
  }
  const auto [best, best_error, best_heading] = best_candidate(now, c.bearing_rad);
  const double margin = config_.switch_margin_deg * std::numbers::pi / 180.0;
  if (best < 0 || best == gait_ || (gait_ >= 0 && best_error + margin >= keep_error)) return c;
  gait_ = best;
  periods_ = 0;
  segment_start_m_ = now.position_m;
  segment_expected_rad_ = best_heading;
  segment_corrected_rad_ = 0.0;
  c.gait = best;
  c.switched = true;
  c.expected_heading_rad = best_heading;
  return c;
}

Steering::Candidate Steering::best_candidate(const Estimate& now, double bearing_rad) const {
  // A face the set has no gait for keeps the current gait (or, at the start, tries them all).
  std::vector<int> candidates = by_face_[now.face];
  if (candidates.empty() && gait_ < 0) {
    for (std::size_t g = 0; g < set_.gaits.size(); ++g) candidates.push_back(static_cast<int>(g));
  }
  Candidate best{-1, 1e300, 0.0};
  for (int g : candidates) {
    const double heading = wrap_rad(now.yaw_rad + heading_rad_[g]);
    const double error = std::abs(wrap_rad(heading - bearing_rad));
    if (error < best.error_rad) best = {g, error, heading};
  }
  return best;
}

void Steering::update(const Estimate& estimate) {
  if (done() || !estimate.located) return;
  const double d = (waypoints_[active_] - estimate.position_m).norm();
  // Inside a margin for the fixes' noise: an estimate 0.1-0.3 m off must not take a
  // waypoint passed 1.6 m wide for one reached.
  const bool passed = best_distance_m_ <= kReachMargin * config_.within_m && d > best_distance_m_ + 0.2;
  if (d <= kReachMargin * config_.within_m || passed) {
    ++active_;
    best_distance_m_ = 1e300;
    return;
  }
  best_distance_m_ = std::min(best_distance_m_, d);
}

}  // namespace tensegrity::drive
