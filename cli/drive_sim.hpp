// SPDX-License-Identifier: Apache-2.0
#pragma once
// `drive --sim`: the steering (ground/drive/) driving the in-process model. The end
// caps' control cores play the gaits as the firmware does, swapping a newly loaded
// table in at a period boundary; the steering sees only the emulated accelerometers
// and position fixes (sim/model/endcap_sensors.hpp). The model's own pose is used for
// the figures reported (how near each waypoint the robot truly came), never to steer.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "robot/gait_set.hpp"
#include "robot/robot.hpp"
#include "sim/model/endcap_sensors.hpp"

namespace tensegrity::cli {

struct DriveSimOptions {
  std::vector<Eigen::Vector2d> waypoints_m;  // world frame, from the settled start's centre
  double within_m = 1.5;
  std::uint64_t seed = 1;
  double time_limit_s = 0.0;  // physics; 0: 90 s per waypoint
  double accelerometer_hz = 20.0;
  double fix_hz = 1.0;
  // The steering chooses this long before a period boundary, the time an upload takes.
  double decide_before_s = 0.5;
  sim::SensorNoise noise;
  std::string record;  // CSV of the path (10 Hz), when set
};

struct WaypointOutcome {
  Eigen::Vector2d target_m = Eigen::Vector2d::Zero();
  bool reached = false;  // the robot's centre came within within_m
  double time_s = 0.0;   // of its closest approach
  double miss_m = 0.0;   // closest approach while it was the steering's target
};

struct DriveOutcome {
  std::vector<WaypointOutcome> waypoints;
  double time_s = 0.0;     // physics
  bool completed = false;  // the steering reached every waypoint within the time limit
  int periods = 0;
  int switches = 0;
  int face_changes = 0;  // seen by the accelerometers
  // The end caps' tension guard: control steps in which it cut a motor's shortening,
  // in all and in the period after a table swap; latched faults; steps with a cable
  // above the hard limit in the model.
  long cutoff_steps = 0;
  long cutoff_steps_after_switch = 0;
  int faults = 0;
  int hard_limit_steps = 0;
  std::string stopped_by;  // why it ended early, empty when it did not
};

// One line per period boundary, for progress on the terminal.
struct DriveProgress {
  double time_s = 0.0;
  Eigen::Vector2d estimate_m = Eigen::Vector2d::Zero();
  std::size_t waypoint = 0;
  double distance_m = 0.0;  // estimated, to the waypoint
  std::string gait;
  std::string face;
  bool switched = false;
};

DriveOutcome drive_sim(const sim::Robot& robot, const sim::GaitSet& set, const DriveSimOptions& options,
                       const std::function<void(const DriveProgress&)>& progress);

}  // namespace tensegrity::cli
