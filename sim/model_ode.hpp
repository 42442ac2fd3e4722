// SPDX-License-Identifier: Apache-2.0
#pragma once
// Private to sim/model*.cpp: the ODE objects behind a Model, and small conversions.
#include <ode/ode.h>

#include <Eigen/Core>
#include <vector>

#include "sim/model.hpp"

namespace tensegrity::sim {
namespace ode_detail {

inline Eigen::Vector3d vec(const dReal* v) { return {v[0], v[1], v[2]}; }
// ODE keeps rotations as 3x4 row-major matrices; column 2 is the body z axis, which
// is the strut's axis here.
inline Eigen::Vector3d axis_of(const dReal* R) { return {R[2], R[6], R[10]}; }
inline Eigen::Matrix3d rotation_of(const dReal* R) {
  Eigen::Matrix3d m;
  m << R[0], R[1], R[2], R[4], R[5], R[6], R[8], R[9], R[10];
  return m;
}

}  // namespace ode_detail

struct Model::Ode {
  dWorldID world = nullptr;
  dJointGroupID contacts = nullptr;
  // ODE's default stepping "threading" implementation is one process-wide object
  // with fake (non-atomic) locks: two worlds stepped on two threads corrupt it. A
  // self-threaded implementation per world makes worlds independent.
  dThreadingImplementationID threading = nullptr;
  std::vector<dBodyID> bodies;
  std::vector<Eigen::Vector3d> inertia_diag;  // body frame, kg m^2
  ~Ode() {
    if (contacts != nullptr) dJointGroupDestroy(contacts);
    if (world != nullptr) {
      dWorldSetStepThreadingImplementation(world, nullptr, nullptr);
      dWorldDestroy(world);
    }
    if (threading != nullptr) dThreadingFreeImplementation(threading);
  }
};

}  // namespace tensegrity::sim
