// SPDX-License-Identifier: Apache-2.0
#include "sim/model/endcap_sensors.hpp"

#include <Eigen/Geometry>

namespace tensegrity::sim {

EndcapSensors::EndcapSensors(const Robot& robot, std::uint64_t seed, const SensorNoise& noise)
    : other_end_(robot.node_count(), 0),
      strut_(robot.node_count(), 0),
      first_end_(robot.node_count(), false),
      noise_(noise),
      random_(seed),
      velocity_(robot.node_count(), Eigen::Vector3d::Zero()),
      velocity_at_reading_(robot.node_count(), Eigen::Vector3d::Zero()) {
  for (std::size_t s = 0; s < robot.struts.size(); ++s) {
    const auto& st = robot.struts[s];
    other_end_[st.node_a] = st.node_b;
    other_end_[st.node_b] = st.node_a;
    strut_[st.node_a] = strut_[st.node_b] = static_cast<int>(s);
    first_end_[st.node_a] = true;
  }
}

void EndcapSensors::observe(const Model& model) {
  // Velocity over the last kVelocitySteps steps: a step's own difference carries the
  // contacts' step-to-step jitter, which no sensor's bandwidth would pass.
  history_.push_back(model.node_positions());
  if (history_.size() > kVelocitySteps + 1) history_.pop_front();
  const auto span = static_cast<double>(history_.size() - 1) * model.dt_s();
  if (span > 0.0) {
    for (std::size_t i = 0; i < velocity_.size(); ++i) velocity_[i] = (history_.back()[i] - history_.front()[i]) / span;
  }
  time_s_ += model.dt_s();
}

std::vector<Eigen::Vector3d> EndcapSensors::accelerations(const Model& model) {
  const std::vector<Eigen::Vector3d> p = model.node_positions();
  const ModelState state = model.save();
  const double span_s = time_s_ - reading_time_s_;
  std::vector<Eigen::Vector3d> out(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Eigen::Vector3d accel =
        span_s > 0.0 ? Eigen::Vector3d((velocity_[i] - velocity_at_reading_[i]) / span_s) : Eigen::Vector3d::Zero();
    const Eigen::Vector3d specific = 1.0 * accel + Eigen::Vector3d(0.0, 0.0, model.robot().gravity_m_per_s2);
    // The end cap's frame: z out along the strut, x the strut body's x axis made
    // square to it (turned half a turn about y at the strut's other end).
    const Eigen::Vector3d z = (p[i] - p[other_end_[i]]).normalized();
    const double* q = &state.body[static_cast<std::size_t>(strut_[i]) * 13 + 3];
    const Eigen::Quaterniond turn(q[0], q[1], q[2], q[3]);
    Eigen::Vector3d x = turn.normalized() * Eigen::Vector3d::UnitX();
    if (!first_end_[i]) x = -x;
    x = (x - x.dot(z) * z).normalized();
    const Eigen::Vector3d y = z.cross(x);
    Eigen::Vector3d reading(x.dot(specific), y.dot(specific), z.dot(specific));
    for (int k = 0; k < 3; ++k) reading[k] += noise_.acceleration_m_per_s2 * normal_(random_);
    out[i] = reading;
  }
  velocity_at_reading_ = velocity_;
  reading_time_s_ = time_s_;
  return out;
}

Eigen::Vector2d EndcapSensors::fix(const Model& model) {
  const Eigen::Vector3d c = model.centre_m();
  return {c.x() + noise_.fix_m * normal_(random_), c.y() + noise_.fix_m * normal_(random_)};
}

}  // namespace tensegrity::sim
