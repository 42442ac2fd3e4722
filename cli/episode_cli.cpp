// SPDX-License-Identifier: Apache-2.0
#include "cli/episode_cli.hpp"

#include <cstdio>
#include <string>

#include "sim/model/core_controller.hpp"
#include "robot/policy.hpp"

namespace tensegrity::cli {

sim::Robot load_robot_arg(const std::string& path, const std::string& policy) {
  if (!path.empty()) return sim::load_robot(path);
  return sim::load_robot(policy.empty() ? sim::default_robot_path() : sim::robot_path_for_policy(policy));
}

void print_heading(const sim::Travel& t, const std::vector<int>& face) {
  std::string on = "no hull face";
  if (face.size() == 3)
    on = "face " + std::to_string(face[0]) + "-" + std::to_string(face[1]) + "-" + std::to_string(face[2]);
  if (t.heading_deg) {
    std::printf("  heading        %+8.1f deg in the start frame (dx %.3f, dy %.3f; %s, yaw %+.1f deg)\n",
                *t.heading_deg, t.start_m.x(), t.start_m.y(), on.c_str(), t.yaw_deg);
  } else {
    std::printf("  heading        none (the robot did not move; %s, yaw %+.1f deg)\n", on.c_str(), t.yaw_deg);
  }
}

void print_episode_summary(const sim::EpisodeResult& r) {
  if (r.feasible) {
    std::printf("  distance       %8.3f m  (dx %.3f, dy %.3f)\n", r.distance_m, r.displacement_m.x(),
                r.displacement_m.y());
    print_heading(r.travel, r.start_face);
  } else {
    std::printf("  INFEASIBLE at t = %.3f s: %s\n", r.infeasible_time_s, r.infeasible_reason.c_str());
  }
  std::printf("  tension        mean %.1f N, max %.1f N\n", r.mean_tension_n, r.max_tension_n);
  std::printf("  motors         %.1f J, %.2f W per cable on average\n", r.motor_energy_j, r.mean_motor_power_w);
  std::printf("  strut spin     %.2f rad/s RMS, %.2f max about their axes; %d end caps touched the ground\n",
              r.axial_spin_rms_rad_per_s, r.axial_spin_max_rad_per_s, r.endcaps_touched_ground);
  std::printf("  strut gap      %.3f m at the closest; struts overlapped for %.2f s\n", r.min_strut_gap_m,
              r.strut_overlap_s);
  std::printf("  time           %.2f s simulated in %.3f s wall (%.0fx real time)\n", r.sim_time_s, r.wall_time_s,
              r.real_time_factor());
}

std::unique_ptr<sim::Controller> make_policy_controller(const sim::Robot& robot, const std::string& path) {
  const sim::Policy policy = sim::load_policy(path, robot);
  return std::make_unique<sim::CoreController>(robot, policy);
}

}  // namespace tensegrity::cli
