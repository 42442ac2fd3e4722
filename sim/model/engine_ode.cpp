// SPDX-License-Identifier: Apache-2.0
// The ODE engine (the default): soft ground contacts generated directly from the end
// caps' heights, strut contacts from the Model's overlaps, dWorldStep.
#include <ode/ode.h>

#include <bit>
#include <cstdarg>
#include <cstdio>
#include <mutex>
#include <string>
#include <vector>

#include "sim/model/engine.hpp"
#include "sim/model/model.hpp"
#include "sim/model/terrain.hpp"

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

Eigen::Vector3d vec(const dReal* v) { return {v[0], v[1], v[2]}; }

// A step that ODE aborted (ode_fault threw out of it) leaves jobs queued in its
// world's stepping object, and freeing that object then trips ODE's own check, which
// would throw out of a destructor and terminate (found by fuzz_robot_file). ODE's
// shutdown and cleanup calls do not empty the queue, so such an object is held here
// for the life of the process: counted and reachable, not lost (LeakSanitizer, which
// the fuzzers run, reports lost memory only).
struct HeldSteppers {
  std::mutex mutex;
  std::vector<dThreadingImplementationID> held;
};
HeldSteppers& held_steppers() {
  static auto* steppers = new HeldSteppers;  // never destroyed: outlives every world
  return *steppers;
}
void hold_stepper(dThreadingImplementationID stepper) {
  HeldSteppers& s = held_steppers();
  const std::lock_guard lock(s.mutex);
  s.held.push_back(stepper);
  // Said at 1, 2, 4, 8, ... so that a process that keeps diverging is noticed.
  if (std::has_single_bit(s.held.size())) {
    std::fprintf(stderr,
                 "sim: %zu ODE world(s) aborted a step in this process; each keeps about 66 kB ODE cannot free\n",
                 s.held.size());
  }
}

class OdeEngine final : public Engine {
 public:
  OdeEngine(const Robot& robot, double dt_s) : robot_(robot), terrain_(robot) {
    init_ode_for_this_thread();
    world_ = dWorldCreate();
    // ODE's default stepping "threading" implementation is one process-wide object
    // with fake (non-atomic) locks: two worlds stepped on two threads corrupt it. A
    // self-threaded implementation per world makes worlds independent.
    threading_ = dThreadingAllocateSelfThreadedImplementation();
    dWorldSetStepThreadingImplementation(world_, dThreadingImplementationGetFunctions(threading_), threading_);
    contacts_ = dJointGroupCreate(0);
    dWorldSetAutoDisableFlag(world_, 0);
    for (const auto& strut : robot.struts) {
      const double length = (robot.nodes_m[strut.node_b] - robot.nodes_m[strut.node_a]).norm();
      dBodyID body = dBodyCreate(world_);
      dMass mass;
      dMassSetCapsuleTotal(&mass, robot.strut_mass_kg, 3, robot.strut_radius_m, length);
      dBodySetMass(body, &mass);
      bodies_.push_back(body);
      inertia_.emplace_back(mass.I[0], mass.I[5], mass.I[10]);
    }
    // Soft contact from the robot file's stiffness and damping (docs/design/model.md).
    const double kp = robot.contact_stiffness_n_per_m;
    const double kd = robot.contact_damping_n_s_per_m;
    soft_erp_ = dt_s * kp / (dt_s * kp + kd);
    soft_cfm_ = 1.0 / (dt_s * kp + kd);
  }
  ~OdeEngine() override {
    dJointGroupDestroy(contacts_);
    dWorldSetStepThreadingImplementation(world_, nullptr, nullptr);
    dWorldDestroy(world_);
    if (aborted_) {
      hold_stepper(threading_);
    } else {
      dThreadingFreeImplementation(threading_);
    }
  }
  OdeEngine(const OdeEngine&) = delete;
  OdeEngine& operator=(const OdeEngine&) = delete;

  BodyState body(int strut) const override {
    dBodyID b = bodies_[strut];
    const dReal* q = dBodyGetQuaternion(b);
    const dReal* R = dBodyGetRotation(b);  // 3x4 row-major
    BodyState s;
    s.position_m = vec(dBodyGetPosition(b));
    s.quaternion_wxyz = {q[0], q[1], q[2], q[3]};
    s.rotation << R[0], R[1], R[2], R[4], R[5], R[6], R[8], R[9], R[10];
    s.velocity_m_per_s = vec(dBodyGetLinearVel(b));
    s.angular_velocity_rad_per_s = vec(dBodyGetAngularVel(b));
    return s;
  }

  void set_body(int strut, const BodyState& s) override {
    dBodyID b = bodies_[strut];
    dBodySetPosition(b, s.position_m.x(), s.position_m.y(), s.position_m.z());
    const dQuaternion q = {s.quaternion_wxyz[0], s.quaternion_wxyz[1], s.quaternion_wxyz[2], s.quaternion_wxyz[3]};
    dBodySetQuaternion(b, q);
    const auto& v = s.velocity_m_per_s;
    const auto& w = s.angular_velocity_rad_per_s;
    dBodySetLinearVel(b, v.x(), v.y(), v.z());
    dBodySetAngularVel(b, w.x(), w.y(), w.z());
  }

  void set_velocity(int strut, const Eigen::Vector3d& v, const Eigen::Vector3d& w) override {
    dBodySetLinearVel(bodies_[strut], v.x(), v.y(), v.z());
    dBodySetAngularVel(bodies_[strut], w.x(), w.y(), w.z());
  }

  void set_gravity(const Eigen::Vector3d& g) override { dWorldSetGravity(world_, g.x(), g.y(), g.z()); }

  void add_force_torque(int strut, const Eigen::Vector3d& f, const Eigen::Vector3d& t) override {
    dBodyAddForce(bodies_[strut], f.x(), f.y(), f.z());
    dBodyAddTorque(bodies_[strut], t.x(), t.y(), t.z());
  }

  ContactReport step(double dt_s, const StepInput& in) override {
    ContactReport report;
    if (in.ground) add_ground_contacts(in, report);
    add_strut_contacts(in, report);
    try {
      dWorldStep(world_, dt_s);
    } catch (...) {
      aborted_ = true;
      throw;
    }
    dJointGroupEmpty(contacts_);
    return report;
  }

  void discard_step() override { dJointGroupEmpty(contacts_); }

  Eigen::Vector3d inertia_diag(int strut) const override { return inertia_[strut]; }

 private:
  dContact soft_contact() const {
    dContact contact{};
    contact.surface.mode = dContactApprox1 | dContactSoftERP | dContactSoftCFM;
    contact.surface.mu = robot_.ground_friction;
    contact.surface.soft_erp = soft_erp_;
    contact.surface.soft_cfm = soft_cfm_;
    return contact;
  }

  // A capsule meets the ground only with its end spheres (the ground's bumps are far
  // wider than a strut is thick), so two sphere tests per strut replace ODE's broad
  // phase and colliders (which are also not thread-safe in Debian's build).
  void add_ground_contacts(const StepInput& in, ContactReport& report) {
    const double r = robot_.strut_radius_m;
    dContact contact = soft_contact();
    if (robot_.ground_restitution > 0.0) {
      contact.surface.mode |= dContactBounce;
      contact.surface.bounce = robot_.ground_restitution;
    }
    GroundContact touch;
    for (std::size_t node = 0; node < in.node_pos_m.size(); ++node) {
      if (!terrain_.touches(in.node_pos_m[node], r, touch)) continue;
      for (int k = 0; k < 3; ++k) {
        contact.geom.pos[k] = touch.point_m[k];
        contact.geom.normal[k] = touch.normal[k];
      }
      contact.geom.depth = touch.depth_m;
      dJointID joint = dJointCreateContact(world_, contacts_, &contact);
      dJointAttach(joint, bodies_[in.strut_of_node[node]], nullptr);
      ++report.ground_contacts;
      report.ground_mask |= std::uint32_t{1} << node;
    }
  }

  void add_strut_contacts(const StepInput& in, ContactReport& report) {
    dContact contact = soft_contact();
    for (const auto& o : in.overlaps) {
      const Eigen::Vector3d d = o.on_a - o.on_b;
      const double distance = d.norm();
      // ODE's normal points from the second body into the first.
      const Eigen::Vector3d normal = d / distance;
      const Eigen::Vector3d at = 0.5 * (o.on_a + o.on_b);
      for (int k = 0; k < 3; ++k) {
        contact.geom.pos[k] = at[k];
        contact.geom.normal[k] = normal[k];
      }
      contact.geom.depth = 2.0 * robot_.strut_radius_m - distance;
      dJointID joint = dJointCreateContact(world_, contacts_, &contact);
      dJointAttach(joint, bodies_[o.strut_a], bodies_[o.strut_b]);
      ++report.strut_contacts;
    }
  }

  const Robot& robot_;
  Terrain terrain_;
  dWorldID world_ = nullptr;
  dJointGroupID contacts_ = nullptr;
  dThreadingImplementationID threading_ = nullptr;
  std::vector<dBodyID> bodies_;
  std::vector<Eigen::Vector3d> inertia_;
  bool aborted_ = false;
  double soft_erp_ = 0.0;
  double soft_cfm_ = 0.0;
};

}  // namespace

std::size_t ode_steppers_held_after_abort() {
  HeldSteppers& s = held_steppers();
  const std::lock_guard lock(s.mutex);
  return s.held.size();
}

Eigen::Vector3d capsule_inertia_diag(double mass_kg, double radius_m, double length_m) {
  dMass mass;
  dMassSetCapsuleTotal(&mass, mass_kg, 3, radius_m, length_m);
  return {mass.I[0], mass.I[5], mass.I[10]};
}

std::unique_ptr<Engine> make_ode_engine(const Robot& robot, double dt_s) {
  return std::make_unique<OdeEngine>(robot, dt_s);
}

}  // namespace tensegrity::sim
