// SPDX-License-Identifier: Apache-2.0
#pragma once
// The robot description: geometry, masses, cables and their owners, actuator limits,
// ground and start. Loaded from JSON (robots/*.json) and validated field by field.
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/limits.hpp"

namespace tensegrity::sim {

class RobotError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CableSpec {
  int node_a = 0;
  int node_b = 0;
  int owner = 0;  // end cap (node) whose motor drives this cable
  double stiffness_n_per_m = 0.0;
  double damping_n_s_per_m = 0.0;
};

struct StrutSpec {
  int node_a = 0;
  int node_b = 0;
};

// Where cables pull on a strut: `axis`, at the end-cap centre on the strut's axis
// (no cable can turn a strut about its own axis); `surface`, on the end cap's
// surface, radius_m off the axis toward the cable's other end, as on the hardware
// and in NTRT (tgRodInfo::getConnectionPoint), so cable forces resist axial spin.
enum class CableAttachment { axis, surface };

struct Robot {
  std::string name;
  std::vector<Eigen::Vector3d> nodes_m;
  std::vector<StrutSpec> struts;
  std::vector<CableSpec> cables;
  double strut_mass_kg = 0.0;
  double strut_radius_m = 0.0;
  // Viscous damping of a strut's spin about its own axis (see docs/design/model.md): the
  // cable attachments at real end caps resist it; point-attached cables cannot.
  double axial_damping_n_m_s = 0.0;
  CableAttachment cable_attachment = CableAttachment::axis;  // strut.cable_attachment
  // strut.rod_contact: struts collide with each other as capsules (as rigid bodies do
  // in NTRT's Bullet world). Off, they pass through each other (docs/design/model.md).
  bool rod_contact = false;
  // strut.axial_spin "zeroed": after every step a strut's spin about its own axis is
  // removed, as the Bullet cross-check in docs/reproduction.md does; "free" (default) leaves it to the
  // cables, the ground and axial_damping_n_m_s.
  bool zero_axial_spin = false;
  double initial_rest_length_m = 0.0;
  // cable.damping_law "capped": a cable's damping force is at most its elastic force,
  // as in the author's NTRT (Muscle2P::calculateAndApplyForce, 2014), so a taut cable
  // pulls with between 0 and twice k (L - L0); "linear" (default) leaves it uncapped.
  bool cable_damping_capped = false;
  core::MotorLimits motor;
  double gravity_m_per_s2 = 9.81;
  double time_step_s = 0.001;
  // learning.time_step_s: the step `tensegrity evolve` scores teams at unless --dt is
  // given; the robot's own step when absent. It is the robot's to measure: a coarser
  // step is fit for learning only where every gait learned there rolls within 1 % of
  // its distance at time_step_s (docs/design/performance.md).
  double learning_time_step_s = 0.001;
  // learning.early_end: `tensegrity evolve` ends a team's episode once it provably
  // cannot roll bar_m, bounding the centre's progress by max_speed_m_per_s
  // (docs/design/performance.md). bar_m 0 (absent): every episode runs to its end.
  double early_end_bar_m = 0.0;
  double early_end_max_speed_m_per_s = 0.0;
  // engine: the rigid-body engine under the model (sim/model/engine.hpp), "ode" (default)
  // or "bullet", to tell the model's physics from its engine's.
  enum class PhysicsEngine { ode, bullet };
  PhysicsEngine engine = PhysicsEngine::ode;
  double ground_friction = 1.0;
  double ground_restitution = 0.0;
  double contact_stiffness_n_per_m = 5e5;
  double contact_damping_n_s_per_m = 2e3;
  // ground.slope_deg, ground.slope_azimuth_deg: the ground is a plane tilted this far,
  // falling toward the azimuth (from +x toward +y). The model keeps the ground at z = 0
  // and tilts gravity instead, so x and y are along the slope (docs/design/model.md).
  double ground_slope_deg = 0.0;
  double ground_slope_azimuth_deg = 0.0;
  // ground.rough: bumps on the ground, heights drawn from `seed` at the nodes of a
  // square grid of bump_spacing_m, within [0, bump_height_m] (sim/model/terrain.hpp).
  // bump_height_m 0 (absent): flat.
  struct RoughGround {
    double bump_height_m = 0.0;
    double bump_spacing_m = 0.0;
    std::uint64_t seed = 0;
  };
  RoughGround ground_rough;
  // Start: the lowest end cap's surface this far above the ground, then settle.
  double start_clearance_m = 0.05;
  double settle_s = 4.0;
  // The pose the settled start drops: a closed cable triangle turned face down (the
  // project's default), or the description's own pose, as the Bullet cross-check
  // starts (dropped, 2 s, then scored from wherever it came to lie).
  enum class StartPose { face_down, description };
  StartPose start_pose = StartPose::face_down;
  // FNV-1a 64 of the canonical JSON, as 16 hex digits: names the exact model a
  // policy was learned on.
  std::string hash;

  int node_count() const { return static_cast<int>(nodes_m.size()); }
  int cable_count() const { return static_cast<int>(cables.size()); }
  int endcap_count() const { return node_count(); }
  // Cables owned by end cap `endcap`, in increasing cable index.
  std::vector<int> cables_of(int endcap) const;
};

// Parses and validates; errors name the source and the JSON path of the bad field.
Robot parse_robot(const std::string& json_text, const std::string& source = "robot");
Robot load_robot(const std::filesystem::path& path);
// robots/<name>.json, found via TENSEGRITY_ROBOTS_DIR, the source tree this binary
// was built from, or ./robots (the path is returned even when no such file exists).
std::filesystem::path robot_path_named(const std::string& name);
// The shipped default: robots/superball-paper.json, the paper's simulated SUPERball
// (docs/design/model.md). The 1.7 m hardware (docs/design/robot.md) is robot_path_named("superball").
std::filesystem::path default_robot_path();
// FNV-1a 64-bit of `text`, as 16 lower-case hex digits.
std::string fnv1a64_hex(const std::string& text);

}  // namespace tensegrity::sim
