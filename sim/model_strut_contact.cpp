// SPDX-License-Identifier: Apache-2.0
// Strut against strut: the closest approach of every pair of capsules each step
// (measured always), and contact joints between them when the robot asks for it.
#include <limits>

#include "sim/model.hpp"
#include "sim/model_ode.hpp"

namespace tensegrity::sim {
namespace {

void to_ode(const Eigen::Vector3d& p, dVector3 out) {
  out[0] = p.x();
  out[1] = p.y();
  out[2] = p.z();
  out[3] = 0.0;
}

}  // namespace

void Model::add_strut_contacts() {
  // Six capsules make 15 pairs: the closest points of two segments (ODE's own
  // dClosestLineSegmentPoints, pure and thread-safe) decide overlap exactly, so no
  // broad phase or collider cache is needed (see add_ground_contacts).
  const double r = robot_.strut_radius_m;
  const double kp = robot_.contact_stiffness_n_per_m;
  const double kd = robot_.contact_damping_n_s_per_m;
  dContact contact{};
  contact.surface.mode = dContactApprox1 | dContactSoftERP | dContactSoftCFM;
  contact.surface.mu = robot_.ground_friction;
  contact.surface.soft_erp = dt_s_ * kp / (dt_s_ * kp + kd);
  contact.surface.soft_cfm = 1.0 / (dt_s_ * kp + kd);
  double min_gap = std::numeric_limits<double>::infinity();
  const int struts = static_cast<int>(robot_.struts.size());
  for (int i = 0; i < struts; ++i) {
    for (int j = i + 1; j < struts; ++j) {
      dVector3 a1, a2, b1, b2, on_a, on_b;
      to_ode(node_pos_[robot_.struts[i].node_a], a1);
      to_ode(node_pos_[robot_.struts[i].node_b], a2);
      to_ode(node_pos_[robot_.struts[j].node_a], b1);
      to_ode(node_pos_[robot_.struts[j].node_b], b2);
      dClosestLineSegmentPoints(a1, a2, b1, b2, on_a, on_b);
      const Eigen::Vector3d pa = ode_detail::vec(on_a);
      const Eigen::Vector3d pb = ode_detail::vec(on_b);
      const double distance = (pa - pb).norm();
      min_gap = std::min(min_gap, distance - 2.0 * r);
      // Axes that meet exactly have no normal; the next step will have one.
      if (!robot_.rod_contact || distance >= 2.0 * r || distance < 1e-9) continue;
      // ODE's normal points from the second body into the first.
      const Eigen::Vector3d normal = (pa - pb) / distance;
      const Eigen::Vector3d at = 0.5 * (pa + pb);
      for (int k = 0; k < 3; ++k) {
        contact.geom.pos[k] = at[k];
        contact.geom.normal[k] = normal[k];
      }
      contact.geom.depth = 2.0 * r - distance;
      dJointID joint = dJointCreateContact(ode_->world, ode_->contacts, &contact);
      dJointAttach(joint, ode_->bodies[i], ode_->bodies[j]);
      ++strut_contact_count_;
    }
  }
  min_strut_gap_m_ = min_gap;
}

}  // namespace tensegrity::sim
