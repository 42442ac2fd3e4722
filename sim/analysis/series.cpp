// SPDX-License-Identifier: Apache-2.0
#include "sim/analysis/series.hpp"

#include <algorithm>
#include <cmath>

#include "sim/model/model.hpp"

namespace tensegrity::sim::analysis {

std::vector<double> EpisodeSeries::column(const std::vector<std::vector<double>>& table, int cable,
                                          std::size_t first) const {
  std::vector<double> out;
  for (std::size_t k = first; k < table.size(); ++k) out.push_back(table[k][static_cast<std::size_t>(cable)]);
  return out;
}

std::size_t EpisodeSeries::first_at(double t) const {
  return static_cast<std::size_t>(std::lower_bound(time_s.begin(), time_s.end(), t - 1e-9) - time_s.begin());
}

void SeriesRecorder::begin(const Model& model) {
  out_ = EpisodeSeries{};
  out_.strut_radius_m = model.robot().strut_radius_m;
  record(0.0, model);
}

void SeriesRecorder::record(double time_s, const Model& model) {
  out_.time_s.push_back(time_s);
  out_.node_m.push_back(model.node_positions());
  const auto rest = model.rest_length_m();
  const auto tension = model.tension_n();
  const auto rate = model.rest_length_rate_m_per_s();
  out_.rest_length_m.emplace_back(rest.begin(), rest.end());
  out_.length_m.emplace_back(model.length_m().begin(), model.length_m().end());
  out_.tension_n.emplace_back(tension.begin(), tension.end());
  std::vector<double> power(rest.size(), 0.0);
  for (std::size_t m = 0; m < power.size(); ++m) power[m] = rate[m] < 0.0 ? -tension[m] * rate[m] : 0.0;
  out_.motor_power_w.push_back(std::move(power));
  std::vector<double> spin;
  for (std::size_t s = 0; s < model.robot().struts.size(); ++s) {
    spin.push_back(std::fabs(model.axial_spin_rad_per_s(static_cast<int>(s))));
  }
  out_.axial_spin_rad_per_s.push_back(std::move(spin));
  out_.kinetic_energy_j.push_back(model.kinetic_energy_j());
  out_.gravity_energy_j.push_back(model.gravity_energy_j());
  out_.elastic_energy_j.push_back(model.elastic_energy_j());
}

}  // namespace tensegrity::sim::analysis
