// SPDX-License-Identifier: Apache-2.0
#pragma once
// The robot: struts as capsule bodies, cables as one-sided spring-dampers between
// strut end points whose rest lengths motors drive, a ground plane, and
// (robot.rod_contact) capsules that collide with each other. The bodies live in the
// robot's rigid-body engine (sim/model/engine.hpp: ODE by default, or Bullet); cable
// forces, spin damping and every measure are computed here, the same for both.
#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include "sim/model/engine.hpp"
#include "sim/model/terrain.hpp"
#include "robot/robot.hpp"

namespace tensegrity::sim {

// Thrown when the engine reports an internal error (a diverged world).
class ModelDiverged : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Full dynamic state, enough to restart a run bit-identically from a snapshot.
struct ModelState {
  std::vector<double> body;           // per strut: pos(3) quat(4) linvel(3) angvel(3)
  std::vector<double> rest_length_m;  // per cable
  std::vector<double> tension_n;      // per cable, last computed
};

class Model {
 public:
  Model(const Robot& robot, double dt_s);
  ~Model();
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;

  // Places the struts so that their end caps sit at `nodes_m`, at rest, every rest
  // length at the robot's initial value.
  void place(std::span<const Eigen::Vector3d> nodes_m);
  ModelState save() const;
  void restore(const ModelState& state);

  // One time step: rest lengths move toward `preferred_rest_length_m` at the motor
  // speed (clamped to the limits), cable forces and ground contacts are applied,
  // the world advances by dt.
  void step(std::span<const double> preferred_rest_length_m);

  double dt_s() const { return dt_s_; }
  const Robot& robot() const { return robot_; }
  int cable_count() const { return robot_.cable_count(); }

  // Per cable, as used in the last step (or after place/restore).
  std::span<const double> rest_length_m() const { return rest_length_m_; }
  std::span<const double> length_m() const { return length_m_; }
  std::span<const double> tension_n() const { return tension_n_; }
  std::span<const double> rest_length_rate_m_per_s() const { return rest_rate_m_per_s_; }

  Eigen::Vector3d node_position(int node) const;
  std::vector<Eigen::Vector3d> node_positions() const;
  Eigen::Vector3d centre_m() const;  // mean of the end caps
  double kinetic_energy_j() const;
  double gravity_energy_j() const;  // relative to z = 0, in the tilted gravity of a slope
  double elastic_energy_j() const;
  // Strut spin about its own axis, rad/s.
  double axial_spin_rad_per_s(int strut) const;
  void set_velocity(int strut, const Eigen::Vector3d& linear_m_per_s, const Eigen::Vector3d& angular_rad_per_s);
  bool state_finite() const;
  // The integration blew up (non-finite or absurd speeds); the model stops stepping.
  bool diverged() const { return diverged_; }
  int contact_count() const { return contact_count_; }
  // End caps in contact with the ground in the last step, bit `node` set.
  std::uint32_t ground_contact_mask() const { return ground_mask_; }
  // The closest approach of two struts' surfaces in the last step, m: negative when
  // two capsules overlap (measured whether or not the robot has rod contact).
  double min_strut_gap_m() const { return min_strut_gap_m_; }
  // Strut-strut contact joints made in the last step (robot.rod_contact only).
  int strut_contact_count() const { return strut_contact_count_; }
  // Pairs of struts whose closest approach the last step computed exactly; the others
  // were proven too far apart to touch or to be the closest.
  int strut_pairs_measured() const { return strut_pairs_measured_; }

  // Switches for the energy-conservation test; defaults follow the robot.
  void set_gravity_enabled(bool on);
  void set_ground_enabled(bool on) { ground_enabled_ = on; }
  void set_damping_enabled(bool on) { damping_enabled_ = on; }

 private:
  // Reads every body from the engine into body_ (after place, restore, step).
  void pull_bodies();
  void update_cable_geometry();
  void apply_forces();
  // Closest approach of every pair of struts; overlaps_ when they collide.
  void measure_strut_gaps();  // model_strut_contact.cpp
  struct Approach {
    double distance_m = 0.0;
    Eigen::Vector3d on_a = Eigen::Vector3d::Zero();
    Eigen::Vector3d on_b = Eigen::Vector3d::Zero();
  };
  Approach closest_approach(std::size_t pair) const;  // of the axes of strut_pairs_[pair]
  void remove_axial_spin();
  // Surface attachment: body-frame offsets of every cable end from its end cap centre.
  void init_surface_attachments();
  bool forces_sane() const;

  Robot robot_;
  Terrain terrain_;  // the slope's gravity; the engine makes the ground's contacts
  double dt_s_;
  std::unique_ptr<Engine> engine_;
  std::vector<BodyState> body_;  // per strut, as the engine last reported it
  std::vector<StrutOverlap> overlaps_;
  // Every pair of struts (i < j, in order), the pair that came closest in the last
  // step (only where the search starts: it changes no result) and per strut its axis.
  std::vector<std::pair<int, int>> strut_pairs_;
  std::size_t closest_pair_ = 0;
  std::vector<Eigen::Vector3d> axis_m_;
  // Per strut: half length, and per node the strut and the sign of its end.
  std::vector<double> half_length_m_;
  std::vector<int> strut_of_node_;
  std::vector<double> end_sign_of_node_;
  std::vector<double> rest_length_m_, length_m_, length_rate_m_per_s_, tension_n_, rest_rate_m_per_s_;
  // Per node: world position, velocity, and arm from its strut's centre; per cable
  // the unit vector from node a to node b.
  std::vector<Eigen::Vector3d> node_pos_, node_vel_, node_arm_, unit_, force_, torque_;
  // Per cable: each end's arm from its strut's centre (the node's arm when cables
  // attach on the axis) and, for surface attachment, its body-frame offset.
  std::vector<Eigen::Vector3d> arm_a_, arm_b_, local_a_, local_b_;
  // Surface attachment: the cable's run inside its two end caps (spool at the centre
  // to the eyelet on the surface), so that in the description's pose a cable is as
  // long as between end-cap centres and rest lengths keep their meaning.
  std::vector<double> inner_run_m_;
  bool surface_ = false;
  std::uint32_t ground_mask_ = 0;
  bool ground_enabled_ = true;
  bool damping_enabled_ = true;
  int contact_count_ = 0;
  int strut_contact_count_ = 0;
  int strut_pairs_measured_ = 0;
  double min_strut_gap_m_ = std::numeric_limits<double>::infinity();
  bool diverged_ = false;
};

}  // namespace tensegrity::sim
