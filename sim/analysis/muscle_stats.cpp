// SPDX-License-Identifier: Apache-2.0
#include "sim/analysis/muscle_stats.hpp"

#include <algorithm>
#include <stdexcept>

namespace tensegrity::sim::analysis {

std::vector<MuscleStats> muscle_stats(const EpisodeSeries& series, std::size_t first) {
  const std::size_t end = series.samples();
  if (first >= end) throw std::invalid_argument("muscle_stats: no samples in the window");
  const double n = static_cast<double>(end - first);
  std::vector<MuscleStats> out;
  for (int m = 0; m < series.cables(); ++m) {
    const auto c = static_cast<std::size_t>(m);
    MuscleStats s;
    s.cable = m;
    s.rest_min_m = s.rest_max_m = series.rest_length_m[first][c];
    for (std::size_t k = first; k < end; ++k) {
      const double rest = series.rest_length_m[k][c];
      s.rest_min_m = std::min(s.rest_min_m, rest);
      s.rest_max_m = std::max(s.rest_max_m, rest);
      s.rest_mean_m += rest / n;
      s.length_mean_m += series.length_m[k][c] / n;
      s.tension_mean_n += series.tension_n[k][c] / n;
      s.tension_max_n = std::max(s.tension_max_n, series.tension_n[k][c]);
      s.power_mean_w += series.motor_power_w[k][c] / n;
    }
    out.push_back(s);
  }
  return out;
}

std::vector<RobotSample> robot_series(const EpisodeSeries& series) {
  std::vector<RobotSample> out;
  const double cables = static_cast<double>(std::max(1, series.cables()));
  for (std::size_t k = 0; k < series.samples(); ++k) {
    RobotSample s;
    s.time_s = series.time_s[k];
    for (int m = 0; m < series.cables(); ++m) {
      const auto c = static_cast<std::size_t>(m);
      s.rest_mean_m += series.rest_length_m[k][c] / cables;
      s.length_mean_m += series.length_m[k][c] / cables;
      s.tension_mean_n += series.tension_n[k][c] / cables;
      s.tension_max_n = std::max(s.tension_max_n, series.tension_n[k][c]);
      s.power_mean_w += series.motor_power_w[k][c] / cables;
    }
    s.kinetic_j = series.kinetic_energy_j[k];
    s.elastic_j = series.elastic_energy_j[k];
    s.gravity_j = series.gravity_energy_j[k];
    out.push_back(s);
  }
  return out;
}

std::vector<double> moving_average(const std::vector<double>& values, std::size_t width) {
  std::vector<double> out(values.size(), 0.0);
  const std::size_t half = width / 2;
  for (std::size_t k = 0; k < values.size(); ++k) {
    const std::size_t lo = k >= half ? k - half : 0;
    const std::size_t hi = std::min(values.size(), k + half + 1);
    double sum = 0.0;
    for (std::size_t j = lo; j < hi; ++j) sum += values[j];
    out[k] = sum / static_cast<double>(hi - lo);
  }
  return out;
}

}  // namespace tensegrity::sim::analysis
