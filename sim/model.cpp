// SPDX-License-Identifier: Apache-2.0
#include "sim/model.hpp"

#include <ode/ode.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <mutex>
#include <string>

#include "firmware/core/rate_limit.hpp"
#include "sim/model_ode.hpp"
#include "sim/strut_frame.hpp"

namespace tensegrity::sim {
namespace {

// ODE's debug checks call abort() after the handler returns; throwing instead turns
// a diverged world into an error the episode can report, not a dead process.
[[noreturn]] void ode_fault(int code, const char* message, va_list args) {
  char text[512];
  std::vsnprintf(text, sizeof text, message, args);
  throw ModelDiverged("ODE error " + std::to_string(code) + ": " + text);
}

void init_ode_for_this_thread() {
  static std::once_flag once;
  std::call_once(once, [] {
    dInitODE2(0);
    dSetErrorHandler(ode_fault);
    dSetDebugHandler(ode_fault);
  });
  thread_local const bool allocated = [] {
    dAllocateODEDataForThread(dAllocateMaskAll);
    return true;
  }();
  (void)allocated;
}

using ode_detail::axis_of;
using ode_detail::rotation_of;
using ode_detail::vec;

}  // namespace

Model::Model(const Robot& robot, double dt_s) : robot_(robot), dt_s_(dt_s), ode_(std::make_unique<Ode>()) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) throw RobotError("model: time step must be > 0");
  init_ode_for_this_thread();
  ode_->world = dWorldCreate();
  ode_->threading = dThreadingAllocateSelfThreadedImplementation();
  dWorldSetStepThreadingImplementation(ode_->world, dThreadingImplementationGetFunctions(ode_->threading),
                                       ode_->threading);
  ode_->contacts = dJointGroupCreate(0);
  dWorldSetAutoDisableFlag(ode_->world, 0);
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

    dBodyID body = dBodyCreate(ode_->world);
    dMass mass;
    // A capsule whose end spheres are centred on the end caps.
    dMassSetCapsuleTotal(&mass, robot_.strut_mass_kg, 3, robot_.strut_radius_m, length);
    dBodySetMass(body, &mass);
    ode_->bodies.push_back(body);
    ode_->inertia_diag.emplace_back(mass.I[0], mass.I[5], mass.I[10]);
  }
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

void Model::set_gravity_enabled(bool on) { dWorldSetGravity(ode_->world, 0, 0, on ? -robot_.gravity_m_per_s2 : 0.0); }

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
    dBodyID body = ode_->bodies[s];
    dBodySetPosition(body, centre.x(), centre.y(), centre.z());
    const dQuaternion dq = {q.w(), q.x(), q.y(), q.z()};
    dBodySetQuaternion(body, dq);
    dBodySetLinearVel(body, 0, 0, 0);
    dBodySetAngularVel(body, 0, 0, 0);
  }
  std::fill(rest_length_m_.begin(), rest_length_m_.end(), robot_.initial_rest_length_m);
  std::fill(rest_rate_m_per_s_.begin(), rest_rate_m_per_s_.end(), 0.0);
  update_cable_geometry();
  std::fill(tension_n_.begin(), tension_n_.end(), 0.0);
  diverged_ = false;
}

ModelState Model::save() const {
  ModelState state;
  for (dBodyID body : ode_->bodies) {
    const dReal* p = dBodyGetPosition(body);
    const dReal* q = dBodyGetQuaternion(body);
    const dReal* v = dBodyGetLinearVel(body);
    const dReal* w = dBodyGetAngularVel(body);
    state.body.insert(state.body.end(), {p[0], p[1], p[2], q[0], q[1], q[2], q[3], v[0], v[1], v[2], w[0], w[1], w[2]});
  }
  state.rest_length_m = rest_length_m_;
  state.tension_n = tension_n_;
  return state;
}

void Model::restore(const ModelState& state) {
  if (state.body.size() != ode_->bodies.size() * 13 || state.rest_length_m.size() != rest_length_m_.size()) {
    throw RobotError("model: snapshot does not match this robot");
  }
  for (std::size_t s = 0; s < ode_->bodies.size(); ++s) {
    const double* b = &state.body[s * 13];
    dBodyID body = ode_->bodies[s];
    dBodySetPosition(body, b[0], b[1], b[2]);
    const dQuaternion q = {b[3], b[4], b[5], b[6]};
    dBodySetQuaternion(body, q);
    dBodySetLinearVel(body, b[7], b[8], b[9]);
    dBodySetAngularVel(body, b[10], b[11], b[12]);
  }
  rest_length_m_ = state.rest_length_m;
  tension_n_ = state.tension_n;
  diverged_ = false;
  std::fill(rest_rate_m_per_s_.begin(), rest_rate_m_per_s_.end(), 0.0);
  update_cable_geometry();
}

void Model::update_cable_geometry() {
  for (std::size_t node = 0; node < node_pos_.size(); ++node) {
    const int s = strut_of_node_[node];
    dBodyID body = ode_->bodies[s];
    const Eigen::Vector3d r = (end_sign_of_node_[node] * half_length_m_[s]) * axis_of(dBodyGetRotation(body));
    node_arm_[node] = r;
    node_pos_[node] = vec(dBodyGetPosition(body)) + r;
    node_vel_[node] = vec(dBodyGetLinearVel(body)) + vec(dBodyGetAngularVel(body)).cross(r);
  }
  for (std::size_t m = 0; m < robot_.cables.size(); ++m) {
    const auto& cable = robot_.cables[m];
    Eigen::Vector3d d = node_pos_[cable.node_b] - node_pos_[cable.node_a];
    Eigen::Vector3d dv = node_vel_[cable.node_b] - node_vel_[cable.node_a];
    arm_a_[m] = node_arm_[cable.node_a];
    arm_b_[m] = node_arm_[cable.node_b];
    if (surface_) {
      dBodyID body_a = ode_->bodies[strut_of_node_[cable.node_a]];
      dBodyID body_b = ode_->bodies[strut_of_node_[cable.node_b]];
      const Eigen::Vector3d off_a = rotation_of(dBodyGetRotation(body_a)) * local_a_[m];
      const Eigen::Vector3d off_b = rotation_of(dBodyGetRotation(body_b)) * local_b_[m];
      arm_a_[m] += off_a;
      arm_b_[m] += off_b;
      d += off_b - off_a;
      dv += vec(dBodyGetAngularVel(body_b)).cross(off_b) - vec(dBodyGetAngularVel(body_a)).cross(off_a);
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
      tension = cable.stiffness_n_per_m * stretch;
      if (damping_enabled_) tension += cable.damping_n_s_per_m * length_rate_m_per_s_[m];
      if (tension < 0.0) tension = 0.0;
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
  for (std::size_t s = 0; s < ode_->bodies.size(); ++s) {
    dBodyID body = ode_->bodies[s];
    if (damping_enabled_ && robot_.axial_damping_n_m_s > 0.0) {
      const Eigen::Vector3d axis = axis_of(dBodyGetRotation(body));
      const double spin = vec(dBodyGetAngularVel(body)).dot(axis);
      torque_[s] -= (robot_.axial_damping_n_m_s * spin) * axis;
    }
    dBodyAddForce(body, force_[s].x(), force_[s].y(), force_[s].z());
    dBodyAddTorque(body, torque_[s].x(), torque_[s].y(), torque_[s].z());
  }
}

void Model::add_ground_contacts() {
  contact_count_ = 0;
  ground_mask_ = 0;
  if (!ground_enabled_) return;
  // A capsule meets a plane only with its end spheres, so two sphere tests per strut
  // replace ODE's broad phase (which is also not thread-safe in Debian's build).
  const double r = robot_.strut_radius_m;
  const double kp = robot_.contact_stiffness_n_per_m;
  const double kd = robot_.contact_damping_n_s_per_m;
  const double h = dt_s_;
  dContact contact{};
  contact.surface.mode = dContactApprox1 | dContactSoftERP | dContactSoftCFM;
  if (robot_.ground_restitution > 0.0) {
    contact.surface.mode |= dContactBounce;
    contact.surface.bounce = robot_.ground_restitution;
  }
  contact.surface.mu = robot_.ground_friction;
  contact.surface.soft_erp = h * kp / (h * kp + kd);
  contact.surface.soft_cfm = 1.0 / (h * kp + kd);
  contact.geom.normal[0] = 0;
  contact.geom.normal[1] = 0;
  contact.geom.normal[2] = 1;
  for (std::size_t node = 0; node < node_pos_.size(); ++node) {
    const double depth = r - node_pos_[node].z();
    if (depth <= 0.0) continue;
    contact.geom.pos[0] = node_pos_[node].x();
    contact.geom.pos[1] = node_pos_[node].y();
    contact.geom.pos[2] = node_pos_[node].z() - r;
    contact.geom.depth = depth;
    dJointID joint = dJointCreateContact(ode_->world, ode_->contacts, &contact);
    dJointAttach(joint, ode_->bodies[strut_of_node_[node]], nullptr);
    ++contact_count_;
    ground_mask_ |= std::uint32_t{1} << node;
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
    // Stepping on would hand ODE non-finite numbers; stop here and say so.
    diverged_ = true;
    dJointGroupEmpty(ode_->contacts);
    return;
  }
  add_ground_contacts();
  strut_contact_count_ = 0;
  add_strut_contacts();
  dWorldStep(ode_->world, dt_s_);
  dJointGroupEmpty(ode_->contacts);
}

bool Model::forces_sane() const {
  // A robot of metre-sized struts has no business moving at 1 km/s: past that the
  // integration has diverged, well before the numbers overflow.
  constexpr double kMaxSpeed = 1e3;
  double sum = 0.0;
  for (std::size_t s = 0; s < ode_->bodies.size(); ++s) {
    sum += force_[s].sum() + torque_[s].sum();
    const Eigen::Vector3d v = vec(dBodyGetLinearVel(ode_->bodies[s]));
    const Eigen::Vector3d w = vec(dBodyGetAngularVel(ode_->bodies[s]));
    if (!(v.squaredNorm() < kMaxSpeed * kMaxSpeed) || !(w.squaredNorm() < 1e2 * kMaxSpeed * kMaxSpeed)) return false;
  }
  return std::isfinite(sum);
}

}  // namespace tensegrity::sim
