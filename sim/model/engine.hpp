// SPDX-License-Identifier: Apache-2.0
#pragma once
// The rigid-body engine under a Model (sim/model/model.hpp holds one; nothing else uses
// it). The Model computes cable forces, spin damping and every measure itself;
// the engine owns the six strut bodies, integrates them and makes their contacts.
// Two engines, so that a result can be checked against the other contact model:
// ODE (the default) and Bullet, the engine of NTRT, the paper's simulator.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

#include "robot/robot.hpp"

namespace tensegrity::sim {

// One strut body as the engine holds it. The rotation is the engine's own matrix
// (not recomputed from the quaternion), so that reading a state changes no bit.
struct BodyState {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector4d quaternion_wxyz = Eigen::Vector4d(1.0, 0.0, 0.0, 0.0);
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // columns: body axes in world
  Eigen::Vector3d velocity_m_per_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_rad_per_s = Eigen::Vector3d::Zero();
};

// Two struts whose capsules overlap, at their axes' closest points.
struct StrutOverlap {
  int strut_a = 0;
  int strut_b = 0;
  Eigen::Vector3d on_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d on_b = Eigen::Vector3d::Zero();
};

// What the Model knows at the start of a step that an engine may use for contacts.
struct StepInput {
  std::span<const Eigen::Vector3d> node_pos_m;  // end-cap centres
  std::span<const int> strut_of_node;
  std::span<const StrutOverlap> overlaps;  // only when robot.rod_contact
  bool ground = true;
};

// Contacts the engine made in the step.
struct ContactReport {
  int ground_contacts = 0;
  std::uint32_t ground_mask = 0;  // end caps on the ground, bit `node`
  int strut_contacts = 0;
};

class Engine {
 public:
  virtual ~Engine() = default;
  virtual BodyState body(int strut) const = 0;
  // Position, quaternion and velocities of `state` (its rotation is ignored).
  virtual void set_body(int strut, const BodyState& state) = 0;
  // Velocities only: the pose stays exactly as the engine holds it.
  virtual void set_velocity(int strut, const Eigen::Vector3d& v_m_per_s, const Eigen::Vector3d& w_rad_per_s) = 0;
  // In the ground's frame (sim/model/terrain.hpp: a slope tilts it).
  virtual void set_gravity(const Eigen::Vector3d& g_m_per_s2) = 0;
  // Applied in the next step only.
  virtual void add_force_torque(int strut, const Eigen::Vector3d& force_n, const Eigen::Vector3d& torque_n_m) = 0;
  virtual ContactReport step(double dt_s, const StepInput& input) = 0;
  // Drops the contacts of a step that was abandoned before the world moved.
  virtual void discard_step() {}
  // Principal moments of inertia in the body frame (z along the strut), kg m^2.
  virtual Eigen::Vector3d inertia_diag(int strut) const = 0;
};

// Principal moments of a capsule of total mass `mass_kg` whose axis (body z) is
// `length_m` long between its end spheres' centres: ODE's dMassSetCapsuleTotal, used
// by both engines so that their bodies are the same.
Eigen::Vector3d capsule_inertia_diag(double mass_kg, double radius_m, double length_m);

// Capsules whose end spheres are centred on the end caps, one per strut, with the
// robot's engine (robot.engine).
std::unique_ptr<Engine> make_engine(const Robot& robot, double dt_s);
std::unique_ptr<Engine> make_ode_engine(const Robot& robot, double dt_s);
std::unique_ptr<Engine> make_bullet_engine(const Robot& robot, double dt_s);

// How many stepping objects of ODE worlds whose step aborted (ModelDiverged thrown
// from inside dWorldStep) this process holds: ODE cannot free them (engine_ode.cpp).
std::size_t ode_steppers_held_after_abort();

}  // namespace tensegrity::sim
