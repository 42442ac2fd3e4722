// SPDX-License-Identifier: Apache-2.0
#include "sim/model/model.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

#include "core/rate_limit.hpp"
#include "sim/model/strut_frame.hpp"

namespace tensegrity::sim {

std::unique_ptr<Engine> make_engine(const Robot& robot, double dt_s) {
  return robot.engine == Robot::PhysicsEngine::bullet ? make_bullet_engine(robot, dt_s) : make_ode_engine(robot, dt_s);
}

Model::Model(const Robot& robot, double dt_s) : robot_(robot), terrain_(robot_), dt_s_(dt_s) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) throw RobotError("model: time step must be > 0");
  engine_ = make_engine(robot_, dt_s);
  set_gravity_enabled(true);

  const int nodes = robot_.node_count();
  strut_of_node_.assign(nodes, -1);
  end_sign_of_node_.assign(nodes, 0.0);
  for (std::size_t s = 0; s < robot_.struts.size(); ++s) {
    const auto& strut = robot_.struts[s];
    const double length = (robot_.nodes_m[strut.node_b] - robot_.nodes_m[strut.node_a]).norm();
    half_length_m_.push_back(0.5 * length);
    strut_of_node_[strut.node_a] = static_cast<int>(s);
    strut_of_node_[strut.node_b] = static_cast<int>(s);
    end_sign_of_node_[strut.node_a] = -1.0;
    end_sign_of_node_[strut.node_b] = +1.0;
  }
  body_.resize(robot_.struts.size());
  const int struts = static_cast<int>(robot_.struts.size());
  for (int i = 0; i < struts; ++i) {
    for (int j = i + 1; j < struts; ++j) strut_pairs_.emplace_back(i, j);
  }
  axis_m_.assign(robot_.struts.size(), Eigen::Vector3d::Zero());
  overlaps_.reserve(strut_pairs_.size());
  const auto cables = static_cast<std::size_t>(robot_.cable_count());
  rest_length_m_.assign(cables, robot_.initial_rest_length_m);
  length_m_.assign(cables, 0.0);
  length_rate_m_per_s_.assign(cables, 0.0);
  tension_n_.assign(cables, 0.0);
  rest_rate_m_per_s_.assign(cables, 0.0);
  node_pos_.assign(nodes, Eigen::Vector3d::Zero());
  node_vel_.assign(nodes, Eigen::Vector3d::Zero());
  node_arm_.assign(nodes, Eigen::Vector3d::Zero());
  unit_.assign(cables, Eigen::Vector3d::Zero());
  arm_a_.assign(cables, Eigen::Vector3d::Zero());
  arm_b_.assign(cables, Eigen::Vector3d::Zero());
  surface_ = robot_.cable_attachment == CableAttachment::surface;
  if (surface_) init_surface_attachments();
  force_.assign(robot_.struts.size(), Eigen::Vector3d::Zero());
  torque_.assign(robot_.struts.size(), Eigen::Vector3d::Zero());
  place(robot_.nodes_m);
}

Model::~Model() = default;

void Model::init_surface_attachments() {
  local_a_.assign(robot_.cables.size(), Eigen::Vector3d::Zero());
  local_b_.assign(robot_.cables.size(), Eigen::Vector3d::Zero());
  inner_run_m_.clear();
  for (std::size_t m = 0; m < robot_.cables.size(); ++m) {
    const auto& c = robot_.cables[m];
    local_a_[m] = surface_attachment(robot_, strut_of_node_[c.node_a], c.node_a, c.node_b);
    local_b_[m] = surface_attachment(robot_, strut_of_node_[c.node_b], c.node_b, c.node_a);
    const Eigen::Vector3d& a = robot_.nodes_m[c.node_a];
    const Eigen::Vector3d& b = robot_.nodes_m[c.node_b];
    const auto& strut_a = robot_.struts[strut_of_node_[c.node_a]];
    const auto& strut_b = robot_.struts[strut_of_node_[c.node_b]];
    const Eigen::Vector3d anchor_a = a + strut_frame(robot_.nodes_m, strut_a.node_a, strut_a.node_b) * local_a_[m];
    const Eigen::Vector3d anchor_b = b + strut_frame(robot_.nodes_m, strut_b.node_a, strut_b.node_b) * local_b_[m];
    inner_run_m_.push_back((b - a).norm() - (anchor_b - anchor_a).norm());
  }
}

void Model::set_gravity_enabled(bool on) {
  engine_->set_gravity(terrain_.gravity_m_per_s2(on ? robot_.gravity_m_per_s2 : 0.0));
}

void Model::pull_bodies() {
  for (std::size_t s = 0; s < body_.size(); ++s) body_[s] = engine_->body(static_cast<int>(s));
}

void Model::place(std::span<const Eigen::Vector3d> nodes_m) {
  for (std::size_t s = 0; s < robot_.struts.size(); ++s) {
    const Eigen::Vector3d a = nodes_m[robot_.struts[s].node_a];
    const Eigen::Vector3d b = nodes_m[robot_.struts[s].node_b];
    const Eigen::Vector3d centre = 0.5 * (a + b);
    // Axis attachment keeps its historical orientation (results stay bit for bit);
    // surface attachment needs the pose-following frame.
    const Eigen::Quaterniond q =
        surface_ ? Eigen::Quaterniond(strut_frame(nodes_m, robot_.struts[s].node_a, robot_.struts[s].node_b))
                 : Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), b - a);
    BodyState state;
    state.position_m = centre;
    state.quaternion_wxyz = {q.w(), q.x(), q.y(), q.z()};
    engine_->set_body(static_cast<int>(s), state);
  }
  pull_bodies();
  std::fill(rest_length_m_.begin(), rest_length_m_.end(), robot_.initial_rest_length_m);
  std::fill(rest_rate_m_per_s_.begin(), rest_rate_m_per_s_.end(), 0.0);
  update_cable_geometry();
  std::fill(tension_n_.begin(), tension_n_.end(), 0.0);
  diverged_ = false;
}

ModelState Model::save() const {
  ModelState state;
  for (const BodyState& b : body_) {
    const auto& p = b.position_m;
    const auto& q = b.quaternion_wxyz;
    const auto& v = b.velocity_m_per_s;
    const auto& w = b.angular_velocity_rad_per_s;
    state.body.insert(state.body.end(), {p[0], p[1], p[2], q[0], q[1], q[2], q[3], v[0], v[1], v[2], w[0], w[1], w[2]});
  }
  state.rest_length_m = rest_length_m_;
  state.tension_n = tension_n_;
  return state;
}

void Model::restore(const ModelState& state) {
  if (state.body.size() != body_.size() * 13 || state.rest_length_m.size() != rest_length_m_.size()) {
    throw RobotError("model: snapshot does not match this robot");
  }
  for (std::size_t s = 0; s < body_.size(); ++s) {
    const double* b = &state.body[s * 13];
    BodyState body;
    body.position_m = {b[0], b[1], b[2]};
    body.quaternion_wxyz = {b[3], b[4], b[5], b[6]};
    body.velocity_m_per_s = {b[7], b[8], b[9]};
    body.angular_velocity_rad_per_s = {b[10], b[11], b[12]};
    engine_->set_body(static_cast<int>(s), body);
  }
  pull_bodies();
  rest_length_m_ = state.rest_length_m;
  tension_n_ = state.tension_n;
  diverged_ = false;
  std::fill(rest_rate_m_per_s_.begin(), rest_rate_m_per_s_.end(), 0.0);
  update_cable_geometry();
}

void Model::update_cable_geometry() {
  for (std::size_t node = 0; node < node_pos_.size(); ++node) {
    const BodyState& body = body_[strut_of_node_[node]];
    const Eigen::Vector3d r = (end_sign_of_node_[node] * half_length_m_[strut_of_node_[node]]) * body.rotation.col(2);
    node_arm_[node] = r;
    node_pos_[node] = body.position_m + r;
    node_vel_[node] = body.velocity_m_per_s + body.angular_velocity_rad_per_s.cross(r);
  }
  for (std::size_t m = 0; m < robot_.cables.size(); ++m) {
    const auto& cable = robot_.cables[m];
    Eigen::Vector3d d = node_pos_[cable.node_b] - node_pos_[cable.node_a];
    Eigen::Vector3d dv = node_vel_[cable.node_b] - node_vel_[cable.node_a];
    arm_a_[m] = node_arm_[cable.node_a];
    arm_b_[m] = node_arm_[cable.node_b];
    if (surface_) {
      const BodyState& body_a = body_[strut_of_node_[cable.node_a]];
      const BodyState& body_b = body_[strut_of_node_[cable.node_b]];
      const Eigen::Vector3d off_a = body_a.rotation * local_a_[m];
      const Eigen::Vector3d off_b = body_b.rotation * local_b_[m];
      arm_a_[m] += off_a;
      arm_b_[m] += off_b;
      d += off_b - off_a;
      dv += body_b.angular_velocity_rad_per_s.cross(off_b) - body_a.angular_velocity_rad_per_s.cross(off_a);
    }
    const double span = d.norm();
    const double length = surface_ ? span + inner_run_m_[m] : span;
    length_m_[m] = length;
    unit_[m] = span > 0.0 ? Eigen::Vector3d(d / span) : Eigen::Vector3d::Zero();
    length_rate_m_per_s_[m] = dv.dot(unit_[m]);
  }
}

void Model::apply_forces() {
  for (auto& f : force_) f.setZero();
  for (auto& t : torque_) t.setZero();
  for (std::size_t m = 0; m < robot_.cables.size(); ++m) {
    const auto& cable = robot_.cables[m];
    const double stretch = length_m_[m] - rest_length_m_[m];
    double tension = 0.0;
    // One-sided: a slack cable pushes nothing, and its damper cannot pull it taut.
    if (stretch > 0.0) {
      const double elastic = cable.stiffness_n_per_m * stretch;
      double damping = damping_enabled_ ? cable.damping_n_s_per_m * length_rate_m_per_s_[m] : 0.0;
      if (robot_.cable_damping_capped) damping = std::clamp(damping, -elastic, elastic);
      tension = std::max(0.0, elastic + damping);
    }
    tension_n_[m] = tension;
    if (tension == 0.0) continue;
    const Eigen::Vector3d f = tension * unit_[m];  // pulls node a toward b, b toward a
    const int sa = strut_of_node_[cable.node_a];
    const int sb = strut_of_node_[cable.node_b];
    force_[sa] += f;
    torque_[sa] += arm_a_[m].cross(f);
    force_[sb] -= f;
    torque_[sb] -= arm_b_[m].cross(f);
  }
  for (std::size_t s = 0; s < body_.size(); ++s) {
    if (damping_enabled_ && robot_.axial_damping_n_m_s > 0.0) {
      const Eigen::Vector3d axis = body_[s].rotation.col(2);
      const double spin = body_[s].angular_velocity_rad_per_s.dot(axis);
      torque_[s] -= (robot_.axial_damping_n_m_s * spin) * axis;
    }
    engine_->add_force_torque(static_cast<int>(s), force_[s], torque_[s]);
  }
}

void Model::step(std::span<const double> preferred_rest_length_m) {
  const auto& limits = robot_.motor;
  const double max_step = limits.speed_m_per_s * dt_s_;
  for (std::size_t m = 0; m < rest_length_m_.size(); ++m) {
    const double target =
        core::clamp_to(preferred_rest_length_m[m], limits.min_rest_length_m, limits.max_rest_length_m);
    const double next = core::move_toward(rest_length_m_[m], target, max_step);
    rest_rate_m_per_s_[m] = (next - rest_length_m_[m]) / dt_s_;
    rest_length_m_[m] = next;
  }
  if (diverged_) return;
  update_cable_geometry();
  apply_forces();
  if (!forces_sane()) {
    // Stepping on would hand the engine non-finite numbers; stop here and say so.
    diverged_ = true;
    engine_->discard_step();
    return;
  }
  measure_strut_gaps();
  const ContactReport contacts = engine_->step(dt_s_, StepInput{node_pos_, strut_of_node_, overlaps_, ground_enabled_});
  contact_count_ = contacts.ground_contacts;
  ground_mask_ = contacts.ground_mask;
  strut_contact_count_ = contacts.strut_contacts;
  pull_bodies();
  if (robot_.zero_axial_spin) remove_axial_spin();
}

void Model::remove_axial_spin() {
  for (std::size_t s = 0; s < body_.size(); ++s) {
    const BodyState& body = body_[s];
    const Eigen::Vector3d axis = body.rotation.col(2);
    const Eigen::Vector3d& w = body.angular_velocity_rad_per_s;
    engine_->set_velocity(static_cast<int>(s), body.velocity_m_per_s, w - w.dot(axis) * axis);
  }
  pull_bodies();
}

bool Model::forces_sane() const {
  // A robot of metre-sized struts has no business moving at 1 km/s: past that the
  // integration has diverged, well before the numbers overflow.
  constexpr double kMaxSpeed = 1e3;
  double sum = 0.0;
  for (std::size_t s = 0; s < body_.size(); ++s) {
    sum += force_[s].sum() + torque_[s].sum();
    const Eigen::Vector3d& v = body_[s].velocity_m_per_s;
    const Eigen::Vector3d& w = body_[s].angular_velocity_rad_per_s;
    if (!(v.squaredNorm() < kMaxSpeed * kMaxSpeed) || !(w.squaredNorm() < 1e2 * kMaxSpeed * kMaxSpeed)) return false;
  }
  return std::isfinite(sum);
}

}  // namespace tensegrity::sim
