// SPDX-License-Identifier: Apache-2.0
// Reading a Model's state: end-cap positions, energies, spin (stepping is model.cpp).
#include <cmath>

#include "sim/model.hpp"
#include "sim/model_ode.hpp"

namespace tensegrity::sim {

using ode_detail::axis_of;
using ode_detail::rotation_of;
using ode_detail::vec;

Eigen::Vector3d Model::node_position(int node) const {
  const int s = strut_of_node_[node];
  dBodyID body = ode_->bodies[s];
  return vec(dBodyGetPosition(body)) + (end_sign_of_node_[node] * half_length_m_[s]) * axis_of(dBodyGetRotation(body));
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
  for (std::size_t s = 0; s < ode_->bodies.size(); ++s) {
    dBodyID body = ode_->bodies[s];
    const Eigen::Vector3d v = vec(dBodyGetLinearVel(body));
    dVector3 wb;
    const dReal* w = dBodyGetAngularVel(body);
    dBodyVectorFromWorld(body, w[0], w[1], w[2], wb);
    const Eigen::Vector3d& I = ode_->inertia_diag[s];
    e += 0.5 * robot_.strut_mass_kg * v.squaredNorm() +
         0.5 * (I.x() * wb[0] * wb[0] + I.y() * wb[1] * wb[1] + I.z() * wb[2] * wb[2]);
  }
  return e;
}

double Model::gravity_energy_j() const {
  double e = 0.0;
  for (dBodyID body : ode_->bodies) e += robot_.strut_mass_kg * robot_.gravity_m_per_s2 * dBodyGetPosition(body)[2];
  return e;
}

double Model::elastic_energy_j() const {
  double e = 0.0;
  for (std::size_t m = 0; m < robot_.cables.size(); ++m) {
    Eigen::Vector3d d = node_position(robot_.cables[m].node_b) - node_position(robot_.cables[m].node_a);
    if (surface_) {
      d += rotation_of(dBodyGetRotation(ode_->bodies[strut_of_node_[robot_.cables[m].node_b]])) * local_b_[m] -
           rotation_of(dBodyGetRotation(ode_->bodies[strut_of_node_[robot_.cables[m].node_a]])) * local_a_[m];
    }
    const double stretch = d.norm() + (surface_ ? inner_run_m_[m] : 0.0) - rest_length_m_[m];
    if (stretch > 0.0) e += 0.5 * robot_.cables[m].stiffness_n_per_m * stretch * stretch;
  }
  return e;
}

double Model::axial_spin_rad_per_s(int strut) const {
  dBodyID body = ode_->bodies[strut];
  return vec(dBodyGetAngularVel(body)).dot(axis_of(dBodyGetRotation(body)));
}

void Model::set_velocity(int strut, const Eigen::Vector3d& v, const Eigen::Vector3d& w) {
  dBodySetLinearVel(ode_->bodies[strut], v.x(), v.y(), v.z());
  dBodySetAngularVel(ode_->bodies[strut], w.x(), w.y(), w.z());
}

bool Model::state_finite() const {
  double sum = 0.0;
  for (dBodyID body : ode_->bodies) {
    const dReal* p = dBodyGetPosition(body);
    const dReal* v = dBodyGetLinearVel(body);
    const dReal* w = dBodyGetAngularVel(body);
    sum += p[0] + p[1] + p[2] + v[0] + v[1] + v[2] + w[0] + w[1] + w[2];
  }
  return std::isfinite(sum);
}

}  // namespace tensegrity::sim
