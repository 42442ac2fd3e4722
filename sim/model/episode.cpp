// SPDX-License-Identifier: Apache-2.0
#include "sim/model/episode.hpp"
#include "sim/model/settled_cache.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

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
  // Above the highest bump of rough ground (0 on a plane).
  const double lift = robot.start_clearance_m + robot.strut_radius_m - lowest + Terrain(robot).max_height_m();
  for (auto& p : nodes) p.z() += lift;
  model.place(nodes);
  return model.save();
}

}  // namespace

ModelState drop_state(const Robot& robot, double dt_s) { return dropped(robot, dt_s, robot.nodes_m); }

namespace {

struct SettledCache {
  std::mutex mutex;
  std::map<std::pair<std::string, double>, std::unique_ptr<ModelState>> states;
};

SettledCache& settled_cache() {
  static SettledCache cache;
  return cache;
}

}  // namespace

void forget_settled_state(const Robot& robot, double dt_s) {
  SettledCache& cache = settled_cache();
  const std::lock_guard lock(cache.mutex);
  cache.states.erase({robot.hash + robot.name, resolve_dt(robot, dt_s)});
}

std::size_t settled_states_cached() {
  SettledCache& cache = settled_cache();
  const std::lock_guard lock(cache.mutex);
  return cache.states.size();
}

const ModelState& settled_state(const Robot& robot, double dt_s) {
  dt_s = resolve_dt(robot, dt_s);
  SettledCache& cache = settled_cache();
  const std::lock_guard lock(cache.mutex);
  auto& slot = cache.states[{robot.hash + robot.name, dt_s}];
  if (!slot) {
    Model model(robot, dt_s);
    const bool face_down = robot.start_pose == Robot::StartPose::face_down;
    model.restore(dropped(robot, dt_s, face_down ? face_down_pose(robot) : robot.nodes_m));
    const std::vector<double> hold(robot.cables.size(), robot.initial_rest_length_m);
    const auto steps = static_cast<std::int64_t>(std::llround(robot.settle_s / dt_s));
    for (std::int64_t i = 0; i < steps; ++i) model.step(hold);
    if (!model.state_finite()) throw RobotError(robot.name + ": the robot does not settle (state not finite)");
    slot = std::make_unique<ModelState>(model.save());
  }
  return *slot;
}

namespace {

// What an episode adds up step by step, apart from the stepping itself.
class Tally {
 public:
  Tally(const Robot& robot, const Model& model)
      : struts_(static_cast<int>(robot.struts.size())),
        last_tension_(model.tension_n().begin(), model.tension_n().end()) {}

  // One step's tensions, spin, contacts and strut gaps; `dt` is the step.
  void add(const Model& model, double dt, EpisodeResult& result) {
    for (int s = 0; s < struts_; ++s) {
      const double w = model.axial_spin_rad_per_s(s);
      spin_sq_sum_ += w * w;
      result.axial_spin_max_rad_per_s = std::max(result.axial_spin_max_rad_per_s, std::abs(w));
    }
    touched_ |= model.ground_contact_mask();
    const double gap = model.min_strut_gap_m();
    min_gap_m_ = std::min(min_gap_m_, gap);
    if (gap < 0.0) result.strut_overlap_s += dt;
    const auto tension = model.tension_n();
    const auto rate = model.rest_length_rate_m_per_s();
    step_max_n_ = 0.0;
    for (std::size_t m = 0; m < tension.size(); ++m) {
      const double t = tension[m];
      tension_sum_ += t;
      if (t > step_max_n_) {
        step_max_n_ = t;
        worst_cable_ = m;
      }
      if (rate[m] < 0.0) result.motor_energy_j -= t * rate[m] * dt;
      last_tension_[m] = t;
    }
    result.max_tension_n = std::max(result.max_tension_n, step_max_n_);
  }

  void finish(std::int64_t steps, EpisodeResult& result) const {
    if (steps == 0) return;
    const auto cables = static_cast<double>(last_tension_.size());
    result.mean_tension_n = tension_sum_ / (static_cast<double>(steps) * cables);
    result.mean_motor_power_w = result.motor_energy_j / (result.sim_time_s * cables);
    result.axial_spin_rms_rad_per_s = std::sqrt(spin_sq_sum_ / (static_cast<double>(steps) * std::max(1, struts_)));
    result.endcaps_touched_ground = std::popcount(touched_);
    result.min_strut_gap_m = min_gap_m_;
  }

  const std::vector<double>& last_tension() const { return last_tension_; }
  double step_max_n() const { return step_max_n_; }
  std::size_t worst_cable() const { return worst_cable_; }

 private:
  int struts_;
  std::vector<double> last_tension_;
  double tension_sum_ = 0.0;
  double spin_sq_sum_ = 0.0;
  double min_gap_m_ = std::numeric_limits<double>::infinity();
  std::uint32_t touched_ = 0;
  double step_max_n_ = 0.0;
  std::size_t worst_cable_ = 0;
};

void start_model(Model& model, const Robot& robot, double dt, const EpisodeOptions& options) {
  if (options.start_state != nullptr) {
    model.restore(*options.start_state);
  } else if (options.start == StartKind::settled) {
    model.restore(settled_state(robot, dt));
  } else {
    model.restore(drop_state(robot, dt));
  }
}

void mark_infeasible(EpisodeResult& result, std::string why, double time_s) {
  result.feasible = false;
  result.infeasible_reason = std::move(why);
  result.infeasible_time_s = time_s;
}

// Whether the episode can end at `now_s` of `end_s` under `rule`: from here no
// path of the centre at the rule's speed reaches the bar (|d(T)| <= |d(t)| + v (T - t)).
bool cannot_reach_bar(const EarlyEnd& rule, const Model& model, const Eigen::Vector2d& start, double now_s,
                      double end_s) {
  const double reachable_m = (horizontal(model.centre_m()) - start).norm() + rule.max_speed_m_per_s * (end_s - now_s);
  return reachable_m < rule.bar_m;
}

// Steps between early-end checks: every whole second of simulated time (at least
// every step), or 0 for none. A bar no team could reach in the whole episode (a
// short one) would end every episode at its first second and score that second
// alone: no early end then.
std::int64_t early_end_check_every(const EarlyEnd& rule, std::int64_t steps, double dt) {
  const bool reachable = rule.bar_m <= rule.max_speed_m_per_s * static_cast<double>(steps) * dt;
  return rule.bar_m > 0.0 && reachable ? std::max<std::int64_t>(1, std::llround(1.0 / dt)) : 0;
}

}  // namespace

EpisodeResult run_episode(const Robot& robot, Controller& controller, const EpisodeOptions& options) {
  const double dt = resolve_dt(robot, options.dt_s);
  const auto wall_start = std::chrono::steady_clock::now();
  Model model(robot, dt);
  start_model(model, robot, dt, options);
  controller.reset(robot);
  if (options.telemetry != nullptr) options.telemetry->begin(model);

  std::vector<double> preferred(model.rest_length_m().begin(), model.rest_length_m().end());
  const Eigen::Vector2d start = horizontal(model.centre_m());
  const std::vector<HullFace> faces = hull_faces(robot);
  const std::vector<Eigen::Vector3d> start_nodes = model.node_positions();
  StartFrame frame = start_frame(robot, faces, start_nodes);
  frame.origin_m = start;
  const auto steps = static_cast<std::int64_t>(std::llround(options.duration_s / dt));
  const double hard_limit = robot.motor.hard_limit_tension_n;
  const int every = std::max(1, options.telemetry_every);
  const std::int64_t check_every = early_end_check_every(options.early_end, steps, dt);

  EpisodeResult result;
  if (frame.face >= 0) result.start_face.assign(faces[frame.face].nodes.begin(), faces[frame.face].nodes.end());
  Tally tally(robot, model);
  std::int64_t done = 0;
  for (std::int64_t k = 0; k < steps; ++k) {
    ControlInput input;
    input.step = k;
    input.time_s = static_cast<double>(k) * dt;
    input.dt_s = dt;
    input.tension_n = tally.last_tension();
    input.rest_length_m = model.rest_length_m();
    controller.update(input, preferred);
    try {
      model.step(preferred);
    } catch (const ModelDiverged& e) {
      mark_infeasible(result, std::string("the model diverged: ") + e.what(), input.time_s);
      break;
    }
    ++done;
    if (model.diverged()) {
      mark_infeasible(result, "the model diverged (non-finite or runaway state)", input.time_s);
      break;
    }
    tally.add(model, dt, result);
    const double now = static_cast<double>(k + 1) * dt;
    if (options.telemetry != nullptr && (k + 1) % every == 0) options.telemetry->record(now, model);
    const double step_max = tally.step_max_n();
    if (step_max > hard_limit || !std::isfinite(step_max)) {
      std::ostringstream why;
      why << "cable " << tally.worst_cable() << " tension " << step_max << " N above the hard limit " << hard_limit
          << " N";
      mark_infeasible(result, why.str(), now);
      break;
    }
    if (check_every > 0 && (k + 1) % check_every == 0 && k + 1 < steps &&
        cannot_reach_bar(options.early_end, model, start, now, static_cast<double>(steps) * dt)) {
      result.ended_early = true;
      break;
    }
  }
  if (result.feasible && !model.state_finite()) {
    mark_infeasible(result, "state not finite (the model diverged)", static_cast<double>(done) * dt);
  }
  if (options.telemetry != nullptr) options.telemetry->end();
  if (options.end_state != nullptr) *options.end_state = model.save();

  result.steps = done;
  result.sim_time_s = static_cast<double>(done) * dt;
  if (result.feasible) {
    result.displacement_m = horizontal(model.centre_m()) - start;
    result.distance_m = result.displacement_m.norm();
    result.travel = travel(frame, horizontal(model.centre_m()));
  } else {
    result.travel.yaw_deg = travel(frame, start).yaw_deg;
  }
  tally.finish(done, result);
  result.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return result;
}

}  // namespace tensegrity::sim
