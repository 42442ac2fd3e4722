// SPDX-License-Identifier: Apache-2.0
// Strut against strut: the closest approach of every pair of capsules each step
// (measured always), and the overlaps the ODE engine turns into contact joints when
// the robot asks for rod contact (Bullet finds its own).
#include <ode/ode.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/model/model.hpp"

namespace tensegrity::sim {
namespace {

void to_ode(const Eigen::Vector3d& p, dVector3 out) {
  out[0] = p.x();
  out[1] = p.y();
  out[2] = p.z();
  out[3] = 0.0;
}

// Whether no two points of the segments a0 + s u and b0 + t v (s, t in [0, 1]) come
// closer than `distance_m`. For any n, the separation Q - P = w + t v - s u (w = b0 -
// a0) projects onto n as w.n + t v.n - s u.n, so |Q - P| |n| is at least |w.n| - |u.n|
// - |v.n|; n = u x v makes the two last terms round-off. Squared, it needs no root.
// Parallel axes (n = 0) prove nothing. The margin is far above the round-off of
// doubles of metre-sized numbers, so a pair this test rejects is apart for certain.
bool apart_beyond(const Eigen::Vector3d& a0, const Eigen::Vector3d& u, const Eigen::Vector3d& b0,
                  const Eigen::Vector3d& v, double distance_m) {
  constexpr double kMarginM = 1e-9;
  const Eigen::Vector3d n = u.cross(v);
  const double lhs = std::abs((b0 - a0).dot(n)) - std::abs(u.dot(n)) - std::abs(v.dot(n));
  const double beyond_m = distance_m + kMarginM;
  return lhs > 0.0 && lhs * lhs > beyond_m * beyond_m * n.squaredNorm();
}

}  // namespace

void Model::measure_strut_gaps() {
  // Six capsules make 15 pairs: the closest points of two segments (ODE's own
  // dClosestLineSegmentPoints, pure and thread-safe) decide overlap exactly, so no
  // broad phase or collider cache is needed. Most pairs of a tensegrity cross far
  // apart: a cheap bound skips the exact test for every pair that can neither overlap
  // nor be the closest, which leaves the overlaps (and their order) and the smallest
  // gap exactly as testing all pairs gives them. The pair closest in the last step,
  // measured first, sets the distance to beat.
  const double r = robot_.strut_radius_m;
  for (std::size_t s = 0; s < axis_m_.size(); ++s) {
    axis_m_[s] = node_pos_[robot_.struts[s].node_b] - node_pos_[robot_.struts[s].node_a];
  }
  const std::size_t pairs = strut_pairs_.size();
  double min_gap = std::numeric_limits<double>::infinity();
  Approach first;
  std::size_t next_closest = closest_pair_;
  strut_pairs_measured_ = pairs > 0 ? 1 : 0;
  if (pairs > 0) {
    first = closest_approach(closest_pair_);
    min_gap = std::min(min_gap, first.distance_m - 2.0 * r);
  }
  overlaps_.clear();
  for (std::size_t k = 0; k < pairs; ++k) {
    Approach approach = first;
    if (k != closest_pair_) {
      const auto [i, j] = strut_pairs_[k];
      const Eigen::Vector3d& a0 = node_pos_[robot_.struts[i].node_a];
      const Eigen::Vector3d& b0 = node_pos_[robot_.struts[j].node_a];
      if (apart_beyond(a0, axis_m_[i], b0, axis_m_[j], std::max(2.0 * r, min_gap + 2.0 * r))) continue;
      approach = closest_approach(k);
      ++strut_pairs_measured_;
      if (approach.distance_m - 2.0 * r < min_gap) next_closest = k;
      min_gap = std::min(min_gap, approach.distance_m - 2.0 * r);
    }
    const double distance = approach.distance_m;
    // Axes that meet exactly have no normal; the next step will have one.
    if (!robot_.rod_contact || distance >= 2.0 * r || distance < 1e-9) continue;
    // At most one per pair: reserved in the constructor, so the step allocates nothing.
    overlaps_.push_back(StrutOverlap{strut_pairs_[k].first, strut_pairs_[k].second, approach.on_a, approach.on_b});
  }
  closest_pair_ = next_closest;
  min_strut_gap_m_ = min_gap;
}

Model::Approach Model::closest_approach(std::size_t pair) const {
  dVector3 a1, a2, b1, b2, on_a, on_b;
  const auto& a = robot_.struts[strut_pairs_[pair].first];
  const auto& b = robot_.struts[strut_pairs_[pair].second];
  to_ode(node_pos_[a.node_a], a1);
  to_ode(node_pos_[a.node_b], a2);
  to_ode(node_pos_[b.node_a], b1);
  to_ode(node_pos_[b.node_b], b2);
  dClosestLineSegmentPoints(a1, a2, b1, b2, on_a, on_b);
  Approach approach;
  approach.on_a = {on_a[0], on_a[1], on_a[2]};
  approach.on_b = {on_b[0], on_b[1], on_b[2]};
  approach.distance_m = (approach.on_a - approach.on_b).norm();
  return approach;
}

}  // namespace tensegrity::sim
