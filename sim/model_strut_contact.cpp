// SPDX-License-Identifier: Apache-2.0
// Strut against strut: the closest approach of every pair of capsules each step
// (measured always), and the overlaps the ODE engine turns into contact joints when
// the robot asks for rod contact (Bullet finds its own).
#include <ode/ode.h>

#include <limits>

#include "sim/model.hpp"

namespace tensegrity::sim {
namespace {

void to_ode(const Eigen::Vector3d& p, dVector3 out) {
  out[0] = p.x();
  out[1] = p.y();
  out[2] = p.z();
  out[3] = 0.0;
}

}  // namespace

void Model::measure_strut_gaps() {
  // Six capsules make 15 pairs: the closest points of two segments (ODE's own
  // dClosestLineSegmentPoints, pure and thread-safe) decide overlap exactly, so no
  // broad phase or collider cache is needed.
  const double r = robot_.strut_radius_m;
  double min_gap = std::numeric_limits<double>::infinity();
  overlaps_.clear();
  const int struts = static_cast<int>(robot_.struts.size());
  for (int i = 0; i < struts; ++i) {
    for (int j = i + 1; j < struts; ++j) {
      dVector3 a1, a2, b1, b2, on_a, on_b;
      to_ode(node_pos_[robot_.struts[i].node_a], a1);
      to_ode(node_pos_[robot_.struts[i].node_b], a2);
      to_ode(node_pos_[robot_.struts[j].node_a], b1);
      to_ode(node_pos_[robot_.struts[j].node_b], b2);
      dClosestLineSegmentPoints(a1, a2, b1, b2, on_a, on_b);
      const Eigen::Vector3d pa(on_a[0], on_a[1], on_a[2]);
      const Eigen::Vector3d pb(on_b[0], on_b[1], on_b[2]);
      const double distance = (pa - pb).norm();
      min_gap = std::min(min_gap, distance - 2.0 * r);
      // Axes that meet exactly have no normal; the next step will have one.
      if (!robot_.rod_contact || distance >= 2.0 * r || distance < 1e-9) continue;
      // At most 15 pairs: reserved in the constructor, so the step allocates nothing.
      overlaps_.push_back(StrutOverlap{i, j, pa, pb});
    }
  }
  min_strut_gap_m_ = min_gap;
}

}  // namespace tensegrity::sim
