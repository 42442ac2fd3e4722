// SPDX-License-Identifier: Apache-2.0
#include "ground/drive/estimator.hpp"

#include <cmath>

namespace tensegrity::drive {

Estimator::Estimator(const FaceGeometry& geometry, const EstimatorConfig& config)
    : geometry_(geometry), config_(config), initial_yaw_rad_(config.initial_yaw_rad) {}

void Estimator::correct_yaw(double rad) {
  attitude_ = Eigen::AngleAxisd(rad, Eigen::Vector3d::UnitZ()).toRotationMatrix() * attitude_;
}

void Estimator::add_accelerations(double time_s, std::span<const Eigen::Vector3d> readings) {
  readings_.push_back({time_s, {readings.begin(), readings.end()}});
  while (readings_.size() > 1 && readings_.front().time_s < time_s - config_.average_s) readings_.pop_front();
  std::vector<Eigen::Vector3d> mean(readings.size(), Eigen::Vector3d::Zero());
  for (const Reading& r : readings_) {
    for (std::size_t i = 0; i < mean.size() && i < r.m_per_s2.size(); ++i) {
      mean[i] += r.m_per_s2[i] / static_cast<double>(readings_.size());
    }
  }
  const auto down = geometry_.down(mean);
  if (!down) {
    candidate_ = -1;
    return;
  }
  if (!started_) {
    // The first reading: the robot at rest on its face, turned by the given yaw.
    started_ = true;
    attitude_ = Eigen::AngleAxisd(initial_yaw_rad_, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                sim::face_down_turn(geometry_.faces()[geometry_.nearest_face(*down)].normal);
  }
  // Tip the attitude so the measured down points down, without turning about the vertical.
  attitude_ =
      Eigen::Quaterniond::FromTwoVectors(attitude_ * *down, -Eigen::Vector3d::UnitZ()).toRotationMatrix() * attitude_;
  const int face = geometry_.nearest_face(*down);
  if (face != candidate_) {
    candidate_ = face;
    candidate_since_s_ = time_s;
  }
  if (face == face_ || time_s - candidate_since_s_ < config_.face_hold_s) return;
  if (face_ >= 0) ++face_changes_;
  face_ = face;
}

void Estimator::add_fix(double time_s, const Eigen::Vector2d& position_m) {
  fixes_.push_back({time_s, position_m});
  while (fixes_.size() > 2 && fixes_.front().time_s < time_s - config_.fix_window_s) fixes_.pop_front();
}

Estimate Estimator::estimate(double time_s) const {
  Estimate e;
  e.face = face_;
  if (face_ >= 0) {
    // As start_frame reads a pose: what is left of the attitude once the face is turned down.
    const Eigen::Matrix3d yaw = attitude_ * sim::face_down_turn(geometry_.faces()[face_].normal).transpose();
    e.yaw_rad = std::atan2(yaw(1, 0), yaw(0, 0));
  }
  if (fixes_.empty()) return e;
  e.located = true;
  if (fixes_.size() == 1) {
    e.position_m = fixes_.front().position_m;
    return e;
  }
  // Least-squares line through the fixes: position = a + b (t - mean t).
  double t_mean = 0.0;
  Eigen::Vector2d p_mean = Eigen::Vector2d::Zero();
  for (const Fix& f : fixes_) {
    t_mean += f.time_s;
    p_mean += f.position_m;
  }
  const auto n = static_cast<double>(fixes_.size());
  t_mean /= n;
  p_mean /= n;
  double stt = 0.0;
  Eigen::Vector2d stp = Eigen::Vector2d::Zero();
  for (const Fix& f : fixes_) {
    stt += (f.time_s - t_mean) * (f.time_s - t_mean);
    stp += (f.time_s - t_mean) * (f.position_m - p_mean);
  }
  e.velocity_m_per_s = stt > 0.0 ? Eigen::Vector2d(stp / stt) : Eigen::Vector2d::Zero();
  e.position_m = p_mean + e.velocity_m_per_s * (time_s - t_mean);
  return e;
}

}  // namespace tensegrity::drive
