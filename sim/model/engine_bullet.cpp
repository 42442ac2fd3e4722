// SPDX-License-Identifier: Apache-2.0
// The Bullet engine (robot.engine "bullet"): Debian's Bullet 3.24 in single precision,
// as NTRT's Bullet 2.82 runs it. Capsules collide with a
// static plane and, with strut.rod_contact, with each other, through Bullet's own
// collision detection and its sequential-impulse solver at their defaults (ERP 0.2,
// split impulse, 10 iterations); the robot file's soft-contact stiffness and damping
// are ODE's and do not apply here (docs/design/model.md).
#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <memory>
#include <vector>

#include "sim/model/engine.hpp"
#include "sim/model/terrain.hpp"

namespace tensegrity::sim {
namespace {

btVector3 bt(const Eigen::Vector3d& v) {
  return {static_cast<btScalar>(v.x()), static_cast<btScalar>(v.y()), static_cast<btScalar>(v.z())};
}
Eigen::Vector3d eigen(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

// An end cap counts as on the ground within this gap: Bullet keeps resting contacts
// at about zero distance, within its contact threshold rather than inside the plane.
constexpr double kGroundTouchM = 1e-3;

// A slope is gravity tilted, which this engine takes as it is; bumps would need a
// height field shape here, which it does not have (robot.cpp refuses the file).
const Robot& checked(const Robot& robot) {
  if (Terrain(robot).rough()) {
    throw RobotError(robot.name + ": ground.rough: the bullet engine has no rough ground (a slope it has)");
  }
  return robot;
}

class BulletEngine final : public Engine {
 public:
  BulletEngine(const Robot& robot, double /*dt_s*/)
      : robot_(checked(robot)),
        dispatcher_(&config_),
        world_(&dispatcher_, &broadphase_, &solver_, &config_),
        plane_(btVector3(0, 0, 1), 0) {
    world_.setGravity(bt(Terrain(robot).gravity_m_per_s2(robot.gravity_m_per_s2)));
    btRigidBody::btRigidBodyConstructionInfo ground_info(0, nullptr, &plane_);
    ground_ = std::make_unique<btRigidBody>(ground_info);
    // Bullet multiplies the two bodies' coefficients: the ground carries 1, the
    // struts the robot file's values.
    ground_->setFriction(1);
    ground_->setRestitution(1);
    const int rods = btBroadphaseProxy::DefaultFilter;
    const int ground = btBroadphaseProxy::StaticFilter;
    world_.addRigidBody(ground_.get(), ground, rods);
    for (const auto& strut : robot.struts) {
      const double length = (robot.nodes_m[strut.node_b] - robot.nodes_m[strut.node_a]).norm();
      shapes_.push_back(std::make_unique<btCapsuleShapeZ>(static_cast<btScalar>(robot.strut_radius_m),
                                                          static_cast<btScalar>(length)));
      // The same mass properties as the ODE engine, so that only the engines differ.
      const Eigen::Vector3d inertia = capsule_inertia_diag(robot.strut_mass_kg, robot.strut_radius_m, length);
      inertia_.push_back(inertia);
      btRigidBody::btRigidBodyConstructionInfo info(static_cast<btScalar>(robot.strut_mass_kg), nullptr,
                                                    shapes_.back().get(), bt(inertia));
      info.m_friction = static_cast<btScalar>(robot.ground_friction);
      info.m_restitution = static_cast<btScalar>(robot.ground_restitution);
      auto body = std::make_unique<btRigidBody>(info);
      body->setActivationState(DISABLE_DEACTIVATION);
      world_.addRigidBody(body.get(), rods, robot.rod_contact ? (ground | rods) : ground);
      bodies_.push_back(std::move(body));
    }
  }
  ~BulletEngine() override {
    for (auto& body : bodies_) world_.removeRigidBody(body.get());
    world_.removeRigidBody(ground_.get());
  }
  BulletEngine(const BulletEngine&) = delete;
  BulletEngine& operator=(const BulletEngine&) = delete;

  BodyState body(int strut) const override {
    const btRigidBody& b = *bodies_[strut];
    const btTransform& t = b.getCenterOfMassTransform();
    const btQuaternion q = t.getRotation();
    BodyState s;
    s.position_m = eigen(t.getOrigin());
    s.quaternion_wxyz = {q.w(), q.x(), q.y(), q.z()};
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) s.rotation(i, j) = t.getBasis()[i][j];
    }
    s.velocity_m_per_s = eigen(b.getLinearVelocity());
    s.angular_velocity_rad_per_s = eigen(b.getAngularVelocity());
    return s;
  }

  void set_body(int strut, const BodyState& s) override {
    btRigidBody& b = *bodies_[strut];
    const auto& q = s.quaternion_wxyz;
    const btQuaternion rotation(static_cast<btScalar>(q[1]), static_cast<btScalar>(q[2]), static_cast<btScalar>(q[3]),
                                static_cast<btScalar>(q[0]));
    b.setCenterOfMassTransform(btTransform(rotation, bt(s.position_m)));
    b.setLinearVelocity(bt(s.velocity_m_per_s));
    b.setAngularVelocity(bt(s.angular_velocity_rad_per_s));
    b.clearForces();
    // A moved body's old contact points belong to where it was.
    world_.getBroadphase()->getOverlappingPairCache()->cleanProxyFromPairs(b.getBroadphaseHandle(), &dispatcher_);
    world_.updateSingleAabb(&b);
  }

  void set_velocity(int strut, const Eigen::Vector3d& v, const Eigen::Vector3d& w) override {
    bodies_[strut]->setLinearVelocity(bt(v));
    bodies_[strut]->setAngularVelocity(bt(w));
  }

  void set_gravity(const Eigen::Vector3d& g) override { world_.setGravity(bt(g)); }

  void add_force_torque(int strut, const Eigen::Vector3d& f, const Eigen::Vector3d& t) override {
    bodies_[strut]->applyCentralForce(bt(f));
    bodies_[strut]->applyTorque(bt(t));
  }

  ContactReport step(double dt_s, const StepInput& in) override {
    // Ground on or off is a test switch: off, the plane leaves the world for the step.
    if (!in.ground) world_.removeRigidBody(ground_.get());
    // maxSubSteps 0: exactly one step of dt, no interpolation.
    world_.stepSimulation(static_cast<btScalar>(dt_s), 0);
    if (!in.ground) {
      world_.addRigidBody(ground_.get(), btBroadphaseProxy::StaticFilter, btBroadphaseProxy::DefaultFilter);
    }
    ContactReport report;
    for (int m = 0; m < dispatcher_.getNumManifolds(); ++m) {
      const btPersistentManifold* manifold = dispatcher_.getManifoldByIndexInternal(m);
      const bool with_ground = manifold->getBody0() == ground_.get() || manifold->getBody1() == ground_.get();
      for (int p = 0; p < manifold->getNumContacts(); ++p) {
        if (manifold->getContactPoint(p).getDistance() > 0) continue;
        ++(with_ground ? report.ground_contacts : report.strut_contacts);
      }
    }
    if (in.ground) {
      for (std::size_t node = 0; node < in.node_pos_m.size(); ++node) {
        const double gap = body_node_z(in, static_cast<int>(node)) - robot_.strut_radius_m;
        if (gap <= kGroundTouchM) report.ground_mask |= std::uint32_t{1} << node;
      }
    }
    return report;
  }

  Eigen::Vector3d inertia_diag(int strut) const override { return inertia_[strut]; }

 private:
  // The end cap's height after the step (the input holds it from before).
  double body_node_z(const StepInput& in, int node) const {
    const int s = in.strut_of_node[node];
    const auto& strut = robot_.struts[s];
    const double half = 0.5 * (robot_.nodes_m[strut.node_b] - robot_.nodes_m[strut.node_a]).norm();
    const btTransform& t = bodies_[s]->getCenterOfMassTransform();
    const double sign = node == strut.node_b ? 1.0 : -1.0;
    return t.getOrigin().z() + sign * half * t.getBasis()[2][2];
  }

  const Robot& robot_;
  btDefaultCollisionConfiguration config_;
  btCollisionDispatcher dispatcher_;
  btDbvtBroadphase broadphase_;
  btSequentialImpulseConstraintSolver solver_;
  btDiscreteDynamicsWorld world_;
  btStaticPlaneShape plane_;
  std::unique_ptr<btRigidBody> ground_;
  std::vector<std::unique_ptr<btCapsuleShapeZ>> shapes_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::vector<Eigen::Vector3d> inertia_;
};

}  // namespace

std::unique_ptr<Engine> make_bullet_engine(const Robot& robot, double dt_s) {
  return std::make_unique<BulletEngine>(robot, dt_s);
}

}  // namespace tensegrity::sim
