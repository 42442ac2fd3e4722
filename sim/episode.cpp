// SPDX-License-Identifier: Apache-2.0
#include "sim/episode.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>

namespace tensegrity::sim {
namespace {

double resolve_dt(const Robot& robot, double dt_s) { return dt_s > 0.0 ? dt_s : robot.time_step_s; }

Eigen::Vector2d horizontal(const Eigen::Vector3d& p) { return {p.x(), p.y()}; }

// The description's pose turned so that a closed cable triangle faces straight
// down: the robot then lands on three end caps instead of balancing on an edge,
// where the description's symmetric pose would leave it until round-off tips it.
std::vector<Eigen::Vector3d> face_down_pose(const Robot& robot) {
  const int n = robot.node_count();
  std::vector<std::vector<bool>> linked(n, std::vector<bool>(n, false));
  for (const auto& c : robot.cables) linked[c.node_a][c.node_b] = linked[c.node_b][c.node_a] = true;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : robot.nodes_m) centre += p / n;
  Eigen::Vector3d best_normal(0.0, 0.0, -1.0);
  double best_z = 2.0;
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      for (int c = b + 1; c < n; ++c) {
        if (!linked[a][b] || !linked[b][c] || !linked[a][c]) continue;
        const auto& pa = robot.nodes_m[a];
        Eigen::Vector3d normal = (robot.nodes_m[b] - pa).cross(robot.nodes_m[c] - pa).normalized();
        const Eigen::Vector3d face = (pa + robot.nodes_m[b] + robot.nodes_m[c]) / 3.0;
        if (normal.dot(face - centre) < 0.0) normal = -normal;
        if (normal.z() < best_z - 1e-12) {
          best_z = normal.z();
          best_normal = normal;
        }
      }
    }
  }
  const Eigen::Quaterniond turn = Eigen::Quaterniond::FromTwoVectors(best_normal, -Eigen::Vector3d::UnitZ());
  std::vector<Eigen::Vector3d> nodes;
  for (const auto& p : robot.nodes_m) nodes.push_back(centre + turn * (p - centre));
  return nodes;
}

ModelState dropped(const Robot& robot, double dt_s, std::vector<Eigen::Vector3d> nodes) {
  Model model(robot, resolve_dt(robot, dt_s));
  double lowest = nodes.front().z();
  for (const auto& p : nodes) lowest = std::min(lowest, p.z());
  const double lift = robot.start_clearance_m + robot.strut_radius_m - lowest;
  for (auto& p : nodes) p.z() += lift;
  model.place(nodes);
  return model.save();
}

}  // namespace

ModelState drop_state(const Robot& robot, double dt_s) { return dropped(robot, dt_s, robot.nodes_m); }

const ModelState& settled_state(const Robot& robot, double dt_s) {
  dt_s = resolve_dt(robot, dt_s);
  static std::mutex mutex;
  static std::map<std::pair<std::string, double>, std::unique_ptr<ModelState>> cache;
  const std::lock_guard lock(mutex);
  auto& slot = cache[{robot.hash + robot.name, dt_s}];
  if (!slot) {
    Model model(robot, dt_s);
    model.restore(dropped(robot, dt_s, face_down_pose(robot)));
    const std::vector<double> hold(robot.cables.size(), robot.initial_rest_length_m);
    const auto steps = static_cast<std::int64_t>(std::llround(robot.settle_s / dt_s));
    for (std::int64_t i = 0; i < steps; ++i) model.step(hold);
    if (!model.state_finite()) throw RobotError(robot.name + ": the robot does not settle (state not finite)");
    slot = std::make_unique<ModelState>(model.save());
  }
  return *slot;
}

EpisodeResult run_episode(const Robot& robot, Controller& controller, const EpisodeOptions& options) {
  const double dt = resolve_dt(robot, options.dt_s);
  const auto wall_start = std::chrono::steady_clock::now();
  Model model(robot, dt);
  if (options.start_state != nullptr) {
    model.restore(*options.start_state);
  } else if (options.start == StartKind::settled) {
    model.restore(settled_state(robot, dt));
  } else {
    model.restore(drop_state(robot, dt));
  }
  controller.reset(robot);
  if (options.telemetry != nullptr) options.telemetry->begin(model);

  const std::size_t cables = robot.cables.size();
  std::vector<double> preferred(model.rest_length_m().begin(), model.rest_length_m().end());
  std::vector<double> last_tension(model.tension_n().begin(), model.tension_n().end());
  const Eigen::Vector2d start = horizontal(model.centre_m());
  const auto steps = static_cast<std::int64_t>(std::llround(options.duration_s / dt));
  const double hard_limit = robot.motor.hard_limit_tension_n;
  const int every = std::max(1, options.telemetry_every);

  EpisodeResult result;
  double tension_sum = 0.0;
  double spin_sq_sum = 0.0;
  std::uint32_t touched = 0;
  const int struts = static_cast<int>(robot.struts.size());
  std::int64_t done = 0;
  for (std::int64_t k = 0; k < steps; ++k) {
    ControlInput input;
    input.step = k;
    input.time_s = static_cast<double>(k) * dt;
    input.dt_s = dt;
    input.tension_n = last_tension;
    input.rest_length_m = model.rest_length_m();
    controller.update(input, preferred);
    try {
      model.step(preferred);
    } catch (const ModelDiverged& e) {
      result.feasible = false;
      result.infeasible_reason = std::string("the model diverged: ") + e.what();
      result.infeasible_time_s = static_cast<double>(k) * dt;
      break;
    }
    ++done;
    if (model.diverged()) {
      result.feasible = false;
      result.infeasible_reason = "the model diverged (non-finite or runaway state)";
      result.infeasible_time_s = static_cast<double>(k) * dt;
      break;
    }

    for (int s = 0; s < struts; ++s) {
      const double w = model.axial_spin_rad_per_s(s);
      spin_sq_sum += w * w;
      result.axial_spin_max_rad_per_s = std::max(result.axial_spin_max_rad_per_s, std::abs(w));
    }
    touched |= model.ground_contact_mask();
    const auto tension = model.tension_n();
    const auto rate = model.rest_length_rate_m_per_s();
    double step_max = 0.0;
    std::size_t worst = 0;
    for (std::size_t m = 0; m < cables; ++m) {
      const double t = tension[m];
      tension_sum += t;
      if (t > step_max) {
        step_max = t;
        worst = m;
      }
      if (rate[m] < 0.0) result.motor_energy_j -= t * rate[m] * dt;
      last_tension[m] = t;
    }
    result.max_tension_n = std::max(result.max_tension_n, step_max);
    const double now = static_cast<double>(k + 1) * dt;
    if (options.telemetry != nullptr && (k + 1) % every == 0) options.telemetry->record(now, model);
    if (step_max > hard_limit || !std::isfinite(step_max)) {
      std::ostringstream why;
      why << "cable " << worst << " tension " << step_max << " N above the hard limit " << hard_limit << " N";
      result.feasible = false;
      result.infeasible_reason = why.str();
      result.infeasible_time_s = now;
      break;
    }
  }
  if (result.feasible && !model.state_finite()) {
    result.feasible = false;
    result.infeasible_reason = "state not finite (the model diverged)";
    result.infeasible_time_s = static_cast<double>(done) * dt;
  }
  if (options.telemetry != nullptr) options.telemetry->end();

  result.steps = done;
  result.sim_time_s = static_cast<double>(done) * dt;
  if (result.feasible) {
    result.displacement_m = horizontal(model.centre_m()) - start;
    result.distance_m = result.displacement_m.norm();
  }
  if (done > 0) {
    result.mean_tension_n = tension_sum / (static_cast<double>(done) * static_cast<double>(cables));
    result.mean_motor_power_w = result.motor_energy_j / (result.sim_time_s * static_cast<double>(cables));
    result.axial_spin_rms_rad_per_s = std::sqrt(spin_sq_sum / (static_cast<double>(done) * std::max(1, struts)));
    result.endcaps_touched_ground = std::popcount(touched);
  }
  result.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return result;
}

}  // namespace tensegrity::sim
