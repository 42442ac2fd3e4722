// SPDX-License-Identifier: Apache-2.0
#pragma once
// One episode kept in memory for analysis (Figures 10-12 of Iscen et al.): what the
// per-step telemetry sees, sampled at a fixed rate, as plain arrays the analysis
// functions read. A recorder fills it while `run_episode` runs; tests build it by hand.
#include <Eigen/Core>
#include <vector>

#include "sim/model/telemetry.hpp"

namespace tensegrity::sim::analysis {

struct EpisodeSeries {
  double strut_radius_m = 0.0;  // an end cap touches the ground when z - radius is small
  std::vector<double> time_s;
  // [sample][node], world frame.
  std::vector<std::vector<Eigen::Vector3d>> node_m;
  // [sample][cable]
  std::vector<std::vector<double>> rest_length_m, length_m, tension_n;
  // Motor power: tension x shortening speed, only while the motor shortens its cable
  // under tension (the work `EpisodeResult::motor_energy_j` sums); 0 otherwise.
  std::vector<std::vector<double>> motor_power_w;
  // [sample][strut], |spin about the strut's own axis|.
  std::vector<std::vector<double>> axial_spin_rad_per_s;
  // [sample]
  std::vector<double> kinetic_energy_j, gravity_energy_j, elastic_energy_j;

  std::size_t samples() const { return time_s.size(); }
  int cables() const { return rest_length_m.empty() ? 0 : static_cast<int>(rest_length_m.front().size()); }
  int nodes() const { return node_m.empty() ? 0 : static_cast<int>(node_m.front().size()); }
  // The values of cable `cable` from sample `first` on: one signal.
  std::vector<double> column(const std::vector<std::vector<double>>& table, int cable, std::size_t first = 0) const;
  // The first sample at or after `time_s`.
  std::size_t first_at(double time_s) const;
};

// Fills an EpisodeSeries from `run_episode`'s telemetry: the start, then every recorded
// step (the caller chooses the rate with EpisodeOptions::telemetry_every).
class SeriesRecorder final : public TelemetrySink {
 public:
  explicit SeriesRecorder(EpisodeSeries& out) : out_(out) {}
  void begin(const Model& model) override;
  void record(double time_s, const Model& model) override;

 private:
  EpisodeSeries& out_;
};

}  // namespace tensegrity::sim::analysis
