// SPDX-License-Identifier: Apache-2.0
#pragma once
// One episode: a robot, a controller, a duration, a start; the distance its centre
// travels, whether it stayed feasible, and summary figures.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/model/controller.hpp"
#include "sim/model/model.hpp"
#include "robot/robot.hpp"
#include "robot/start_frame.hpp"
#include "sim/model/telemetry.hpp"

namespace tensegrity::sim {

enum class StartKind {
  settled,  // a cable triangle face down, dropped, settled for settle_s: "from rest"
  drop,     // the description's pose, lowest end cap clearance_m above the ground
};

// Ends an episode once its distance provably cannot reach bar_m: even moving at
// max_speed_m_per_s for the rest of it, the centre would end nearer its start than
// bar_m. Checked every whole second of simulated time. bar_m 0: never.
struct EarlyEnd {
  double bar_m = 0.0;
  double max_speed_m_per_s = 0.0;
};

struct EpisodeOptions {
  double duration_s = 60.0;
  double dt_s = 0.0;  // 0: the robot's time step
  StartKind start = StartKind::settled;
  const ModelState* start_state = nullptr;  // a given pose; overrides `start`
  TelemetrySink* telemetry = nullptr;
  int telemetry_every = 1;  // record every N-th step
  EarlyEnd early_end;
  ModelState* end_state = nullptr;  // when set, the state the episode ended in (to go on from)
};

struct EpisodeResult {
  double distance_m = 0.0;  // horizontal, centre of the end caps, final minus initial
  Eigen::Vector2d displacement_m = Eigen::Vector2d::Zero();
  // The same displacement in the start frame (sim/start_frame.hpp) and its heading;
  // zero and no heading when the episode was infeasible.
  Travel travel;
  std::vector<int> start_face;  // the end caps of the hull face the robot started on
  bool feasible = true;
  std::string infeasible_reason;
  double infeasible_time_s = 0.0;
  double max_tension_n = 0.0;
  double mean_tension_n = 0.0;      // over time and cables
  double motor_energy_j = 0.0;      // work the motors did shortening cables under tension
  double mean_motor_power_w = 0.0;  // per cable
  // How the struts turned about their own axes (a gait must not skate on spinning
  // struts, docs/design/model.md): RMS over struts and steps, and the largest seen.
  double axial_spin_rms_rad_per_s = 0.0;
  double axial_spin_max_rad_per_s = 0.0;
  int endcaps_touched_ground = 0;  // of the robot's end caps, at any step
  // How close two struts came: the smallest gap between their capsules' surfaces
  // (negative: they overlapped, which without strut.rod_contact they may), and for
  // how long any two overlapped.
  double min_strut_gap_m = 0.0;
  double strut_overlap_s = 0.0;
  double sim_time_s = 0.0;
  // Ended by options.early_end at sim_time_s; distance_m is the distance then.
  bool ended_early = false;
  double wall_time_s = 0.0;
  std::int64_t steps = 0;
  double real_time_factor() const { return wall_time_s > 0.0 ? sim_time_s / wall_time_s : 0.0; }
};

// The description's node pose, shifted so the lowest end cap's surface is
// clearance_m above the ground.
ModelState drop_state(const Robot& robot, double dt_s);
// Turned so a closed cable triangle faces down, dropped, and settled for settle_s
// with every rest length at its initial value.
// Computed once per robot and time step, then shared (thread-safe).
const ModelState& settled_state(const Robot& robot, double dt_s);

EpisodeResult run_episode(const Robot& robot, Controller& controller, const EpisodeOptions& options);

}  // namespace tensegrity::sim
