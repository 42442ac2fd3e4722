// SPDX-License-Identifier: Apache-2.0
#include "sim/model/episode_json.hpp"

namespace tensegrity::sim {

nlohmann::json episode_json(const EpisodeResult& r) {
  return {
      {"distance_m", r.distance_m},
      {"displacement_m", {r.displacement_m.x(), r.displacement_m.y()}},
      {"displacement_start_m", {r.travel.start_m.x(), r.travel.start_m.y()}},
      {"heading_deg", r.travel.heading_deg ? nlohmann::json(*r.travel.heading_deg) : nlohmann::json(nullptr)},
      {"start_frame", {{"yaw_deg", r.travel.yaw_deg}, {"face", r.start_face}}},
      {"feasible", r.feasible},
      {"infeasible_reason", r.feasible ? nlohmann::json(nullptr) : nlohmann::json(r.infeasible_reason)},
      {"infeasible_time_s", r.feasible ? nlohmann::json(nullptr) : nlohmann::json(r.infeasible_time_s)},
      {"max_tension_n", r.max_tension_n},
      {"mean_tension_n", r.mean_tension_n},
      {"motor_energy_j", r.motor_energy_j},
      {"mean_motor_power_w", r.mean_motor_power_w},
      {"axial_spin_rms_rad_per_s", r.axial_spin_rms_rad_per_s},
      {"axial_spin_max_rad_per_s", r.axial_spin_max_rad_per_s},
      {"endcaps_touched_ground", r.endcaps_touched_ground},
      {"min_strut_gap_m", r.min_strut_gap_m},
      {"strut_overlap_s", r.strut_overlap_s},
      {"steps", r.steps},
      {"sim_time_s", r.sim_time_s},
      {"wall_time_s", r.wall_time_s},
      {"real_time_factor", r.real_time_factor()},
  };
}

}  // namespace tensegrity::sim
