// SPDX-License-Identifier: Apache-2.0
// Reading a Model's state: end-cap positions, energies, spin (stepping is model.cpp).
#include <cmath>

#include "sim/model/model.hpp"

namespace tensegrity::sim {

Eigen::Vector3d Model::node_position(int node) const {
  const int s = strut_of_node_[node];
  return body_[s].position_m + (end_sign_of_node_[node] * half_length_m_[s]) * body_[s].rotation.col(2);
}

std::vector<Eigen::Vector3d> Model::node_positions() const {
  std::vector<Eigen::Vector3d> out;
  out.reserve(node_pos_.size());
  for (int i = 0; i < robot_.node_count(); ++i) out.push_back(node_position(i));
  return out;
}

Eigen::Vector3d Model::centre_m() const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int i = 0; i < robot_.node_count(); ++i) sum += node_position(i);
  return sum / robot_.node_count();
}

double Model::kinetic_energy_j() const {
  double e = 0.0;
  for (std::size_t s = 0; s < body_.size(); ++s) {
    const Eigen::Vector3d& v = body_[s].velocity_m_per_s;
    const Eigen::Vector3d wb = body_[s].rotation.transpose() * body_[s].angular_velocity_rad_per_s;
    const Eigen::Vector3d I = engine_->inertia_diag(static_cast<int>(s));
    e += 0.5 * robot_.strut_mass_kg * v.squaredNorm() +
         0.5 * (I.x() * wb[0] * wb[0] + I.y() * wb[1] * wb[1] + I.z() * wb[2] * wb[2]);
  }
  return e;
}

double Model::gravity_energy_j() const {
  double e = 0.0;
  if (robot_.ground_slope_deg != 0.0) {
    // On a slope gravity is tilted in the ground's frame: the energy is -m g . p.
    const Eigen::Vector3d g = terrain_.gravity_m_per_s2(robot_.gravity_m_per_s2);
    for (const BodyState& body : body_) e -= robot_.strut_mass_kg * g.dot(body.position_m);
    return e;
  }
  for (const BodyState& body : body_) e += robot_.strut_mass_kg * robot_.gravity_m_per_s2 * body.position_m.z();
  return e;
}

double Model::elastic_energy_j() const {
  double e = 0.0;
  for (std::size_t m = 0; m < robot_.cables.size(); ++m) {
    const int a = robot_.cables[m].node_a;
    const int b = robot_.cables[m].node_b;
    Eigen::Vector3d d = node_position(b) - node_position(a);
    if (surface_)
      d += body_[strut_of_node_[b]].rotation * local_b_[m] - body_[strut_of_node_[a]].rotation * local_a_[m];
    const double stretch = d.norm() + (surface_ ? inner_run_m_[m] : 0.0) - rest_length_m_[m];
    if (stretch > 0.0) e += 0.5 * robot_.cables[m].stiffness_n_per_m * stretch * stretch;
  }
  return e;
}

double Model::axial_spin_rad_per_s(int strut) const {
  return body_[strut].angular_velocity_rad_per_s.dot(body_[strut].rotation.col(2));
}

void Model::set_velocity(int strut, const Eigen::Vector3d& v, const Eigen::Vector3d& w) {
  engine_->set_velocity(strut, v, w);
  body_[strut] = engine_->body(strut);
}

bool Model::state_finite() const {
  double sum = 0.0;
  for (const BodyState& body : body_) {
    sum += body.position_m.sum() + body.velocity_m_per_s.sum() + body.angular_velocity_rad_per_s.sum();
  }
  return std::isfinite(sum);
}

}  // namespace tensegrity::sim
