// SPDX-License-Identifier: Apache-2.0
#include "cli/drive_sim.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>

#include "core/endcap_controller.hpp"
#include "ground/drive/estimator.hpp"
#include "ground/drive/steering.hpp"
#include "robot/start_frame.hpp"
#include "sim/model/episode.hpp"
#include "sim/model/model.hpp"

namespace tensegrity::cli {
namespace {

std::string face_name(const sim::HullFace& f) {
  return std::to_string(f.nodes[0]) + "-" + std::to_string(f.nodes[1]) + "-" + std::to_string(f.nodes[2]);
}

// The end caps' control cores, one per end cap, wired to the model's cables.
class Endcaps {
 public:
  Endcaps(const sim::Robot& robot, const sim::GaitSet& set) {
    for (int e = 0; e < robot.endcap_count(); ++e) {
      core::EndcapConfig config;
      cables_.push_back(robot.cables_of(e));
      config.motor_count = static_cast<std::uint32_t>(cables_.back().size());
      config.limits = robot.motor;
      config.initial_rest_length_m = robot.initial_rest_length_m;
      cores_.emplace_back(config);
    }
    for (const auto& g : set.gaits) {
      tables_.emplace_back();
      for (int e = 0; e < robot.endcap_count(); ++e) tables_.back().push_back(sim::endcap_table(g.policy, robot, e));
    }
  }

  // Idle: plays at once; running: swapped in at the next period boundary.
  void load(int gait) {
    for (std::size_t e = 0; e < cores_.size(); ++e) {
      if (cables_[e].empty()) continue;
      if (cores_[e].load(tables_[gait][e]) != core::TableError::none) {
        throw std::runtime_error("drive: end cap " + std::to_string(e) + " rejected a gait's table");
      }
    }
  }

  void start(const sim::Model& model) {
    std::array<double, core::kMaxMotorsPerEndcap> commanded{};
    for (std::size_t e = 0; e < cores_.size(); ++e) {
      if (cables_[e].empty()) continue;
      for (std::size_t k = 0; k < cables_[e].size(); ++k) commanded[k] = model.rest_length_m()[cables_[e][k]];
      cores_[e].reset_commanded(std::span(commanded.data(), cables_[e].size()));
      cores_[e].start(0);
    }
  }

  struct Summary {
    bool cutoff = false;
    bool faulted = false;
    bool swapped = false;
  };

  Summary step(std::int64_t step, double dt_s, std::span<const double> tension, std::span<double> preferred) {
    const std::int64_t now_ns = step * core::seconds_to_ns(dt_s);
    std::array<double, core::kMaxMotorsPerEndcap> t{};
    std::array<double, core::kMaxMotorsPerEndcap> commanded{};
    Summary s;
    for (std::size_t e = 0; e < cores_.size(); ++e) {
      const auto& cables = cables_[e];
      if (cables.empty()) continue;
      for (std::size_t k = 0; k < cables.size(); ++k) t[k] = tension[cables[k]];
      const core::StepStatus status =
          cores_[e].step(now_ns, dt_s, std::span(t.data(), cables.size()), std::span(commanded.data(), cables.size()));
      for (std::size_t k = 0; k < cables.size(); ++k) preferred[cables[k]] = commanded[k];
      s.cutoff |= status.cutoff_mask != 0;
      s.faulted |= status.mode == core::Mode::faulted;
      s.swapped |= status.table_swapped;
    }
    return s;
  }

 private:
  std::vector<core::EndcapController> cores_;
  std::vector<std::vector<int>> cables_;
  std::vector<std::vector<core::EndcapTable>> tables_;  // per gait, per end cap
};

// One drive: the model, the end caps, the sensors, the estimator and the steering.
class Run {
 public:
  Run(const sim::Robot& robot, const sim::GaitSet& set, const DriveSimOptions& options)
      : robot_(robot),
        set_(set),
        options_(options),
        dt_(robot.time_step_s),
        model_(robot, dt_),
        endcaps_(robot, set),
        sensors_(robot, options.seed, options.noise),
        geometry_(robot),
        period_s_(set.gaits.front().policy.period_s) {
    model_.restore(sim::settled_state(robot, dt_));
    const auto nodes = model_.node_positions();
    // The course's frame is the world's, with its origin at the settled start's centre;
    // the robot is placed with its start frame's yaw known, as an operator would place it.
    const sim::StartFrame frame = sim::start_frame(robot, geometry_.faces(), nodes);
    origin_ = frame.origin_m;
    drive::EstimatorConfig ec;
    ec.initial_yaw_rad = frame.yaw_rad;
    estimator_ = std::make_unique<drive::Estimator>(geometry_, ec);
    drive::SteeringConfig sc;
    sc.within_m = options.within_m;
    steering_ = std::make_unique<drive::Steering>(set, geometry_, options.waypoints_m, sc);
    for (const auto& w : options.waypoints_m) outcome_.waypoints.push_back({w, false, 0.0, 1e300});
    if (!options.record.empty()) {
      record_.open(options.record);
      if (!record_) throw std::runtime_error("drive: --record: cannot write " + options.record);
      record_ << "time_s,x_m,y_m,estimate_x_m,estimate_y_m,face,estimate_face,yaw_deg,estimate_yaw_deg,gait,waypoint\n";
    }
  }

  DriveOutcome run(const std::function<void(const DriveProgress&)>& progress) {
    settle_sensors();
    if (!decide(0.0, progress)) {
      outcome_.stopped_by = "no gait to start with (no face or fix)";
      return outcome_;
    }
    endcaps_.start(model_);
    const double limit_s =
        options_.time_limit_s > 0.0 ? options_.time_limit_s : 90.0 * static_cast<double>(options_.waypoints_m.size());
    const auto steps = static_cast<std::int64_t>(std::llround(limit_s / dt_));
    std::vector<double> preferred(model_.rest_length_m().begin(), model_.rest_length_m().end());
    std::vector<double> tension(model_.tension_n().begin(), model_.tension_n().end());
    for (std::int64_t k = 0; k < steps && !steering_->done(); ++k) {
      const double now = static_cast<double>(k + 1) * dt_;
      if (!control(k, tension, preferred)) break;
      tension.assign(model_.tension_n().begin(), model_.tension_n().end());
      outcome_.time_s = now;
      sense(now);
      track_truth(now);
      const double next_boundary = period_s_ * (std::floor(now / period_s_ + 1e-9) + 1.0);
      if (now + 0.5 * dt_ >= next_boundary - options_.decide_before_s && decided_for_ < next_boundary - 1e-9) {
        decided_for_ = next_boundary;
        decide(now, progress);
      }
    }
    outcome_.completed = steering_->done();
    outcome_.face_changes = estimator_->face_changes();
    for (auto& w : outcome_.waypoints) w.reached = w.miss_m <= options_.within_m;
    return outcome_;
  }

 private:
  // The robot at rest before the start: a few readings and two fixes to begin from.
  void settle_sensors() {
    for (int i = 0; i <= 10; ++i) {
      const auto a = sensors_.accelerations(model_);
      estimator_->add_accelerations(-0.05 * (10 - i), a);
    }
    estimator_->add_fix(-1.0, sensors_.fix(model_) - origin_);
    estimator_->add_fix(0.0, sensors_.fix(model_) - origin_);
  }

  // One control step of the end caps and the model; false when the drive must stop.
  bool control(std::int64_t k, std::span<const double> tension, std::vector<double>& preferred) {
    const auto s = endcaps_.step(k, dt_, tension, preferred);
    if (s.swapped) swapped_at_ = static_cast<double>(k) * dt_;
    if (s.cutoff) {
      ++outcome_.cutoff_steps;
      if (swapped_at_ >= 0.0 && static_cast<double>(k) * dt_ < swapped_at_ + period_s_) {
        ++outcome_.cutoff_steps_after_switch;
      }
    }
    if (s.faulted) {
      ++outcome_.faults;
      outcome_.stopped_by = "an end cap faulted";
      return false;
    }
    try {
      model_.step(preferred);
    } catch (const sim::ModelDiverged& e) {
      outcome_.stopped_by = std::string("the model diverged: ") + e.what();
      return false;
    }
    if (model_.diverged()) {
      outcome_.stopped_by = "the model diverged";
      return false;
    }
    for (double t : model_.tension_n()) {
      if (t > robot_.motor.hard_limit_tension_n) {
        ++outcome_.hard_limit_steps;
        break;
      }
    }
    sensors_.observe(model_);
    return true;
  }

  void sense(double now) {
    if (now + 0.5 * dt_ >= next_accel_s_) {
      next_accel_s_ += 1.0 / options_.accelerometer_hz;
      estimator_->add_accelerations(now, sensors_.accelerations(model_));
      steering_->update(estimator_->estimate(now));
    }
    if (now + 0.5 * dt_ >= next_fix_s_) {
      next_fix_s_ += 1.0 / options_.fix_hz;
      estimator_->add_fix(now, sensors_.fix(model_) - origin_);
    }
  }

  void track_truth(double now) {
    const Eigen::Vector3d c = model_.centre_m();
    const Eigen::Vector2d here = Eigen::Vector2d(c.x(), c.y()) - origin_;
    const std::size_t active = steering_->active();
    if (active < outcome_.waypoints.size()) {
      auto& w = outcome_.waypoints[active];
      const double d = (here - w.target_m).norm();
      if (d < w.miss_m) {
        w.miss_m = d;
        w.time_s = now;
      }
    }
    if (record_ && now + 0.5 * dt_ >= next_record_s_) {
      next_record_s_ += 0.1;
      const auto e = estimator_->estimate(now);
      const auto nodes = model_.node_positions();
      const sim::StartFrame truth = sim::start_frame(robot_, geometry_.faces(), nodes);
      record_ << now << ',' << here.x() << ',' << here.y() << ',' << e.position_m.x() << ',' << e.position_m.y() << ','
              << face_name(geometry_.faces()[truth.face]) << ','
              << (e.face >= 0 ? face_name(geometry_.faces()[e.face]) : "") << ',' << truth.yaw_rad * 180.0 / M_PI << ','
              << e.yaw_rad * 180.0 / M_PI << ",\"" << (gait_ >= 0 ? set_.gaits[gait_].name : "") << "\"," << active
              << '\n';
    }
  }

  // Chooses the next period's gait and loads it (swapped in at the boundary).
  bool decide(double now, const std::function<void(const DriveProgress&)>& progress) {
    const drive::Choice c = steering_->choose(now, *estimator_);
    if (c.gait < 0) return false;
    ++outcome_.periods;
    if (c.switched) {
      endcaps_.load(c.gait);
      if (gait_ >= 0) ++outcome_.switches;
      gait_ = c.gait;
    }
    if (progress) {
      const auto e = estimator_->estimate(now);
      DriveProgress p;
      p.time_s = now;
      p.estimate_m = e.position_m;
      p.waypoint = steering_->active();
      if (!steering_->done()) p.distance_m = (steering_->waypoints()[p.waypoint] - e.position_m).norm();
      p.gait = set_.gaits[gait_].name;
      p.face = e.face >= 0 ? face_name(geometry_.faces()[e.face]) : "?";
      p.switched = c.switched;
      progress(p);
    }
    return true;
  }

  const sim::Robot& robot_;
  const sim::GaitSet& set_;
  DriveSimOptions options_;
  double dt_;
  sim::Model model_;
  Endcaps endcaps_;
  sim::EndcapSensors sensors_;
  drive::FaceGeometry geometry_;
  double period_s_;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  std::unique_ptr<drive::Estimator> estimator_;
  std::unique_ptr<drive::Steering> steering_;
  DriveOutcome outcome_;
  std::ofstream record_;
  int gait_ = -1;
  double swapped_at_ = -1.0;
  double decided_for_ = 0.0;
  double next_accel_s_ = 0.0, next_fix_s_ = 1.0, next_record_s_ = 0.0;
};

}  // namespace

DriveOutcome drive_sim(const sim::Robot& robot, const sim::GaitSet& set, const DriveSimOptions& options,
                       const std::function<void(const DriveProgress&)>& progress) {
  for (const auto& g : set.gaits) {
    if (std::abs(g.policy.period_s - set.gaits.front().policy.period_s) > 1e-9) {
      throw std::runtime_error("drive: the gait set's gaits have different periods; the end caps swap at a boundary");
    }
  }
  Run run(robot, set, options);
  return run.run(progress);
}

}  // namespace tensegrity::cli
