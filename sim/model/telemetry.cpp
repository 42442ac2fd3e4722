// SPDX-License-Identifier: Apache-2.0
#include "sim/model/telemetry.hpp"

#include <stdexcept>

#include "sim/model/model.hpp"

namespace tensegrity::sim {

CsvTelemetry::CsvTelemetry(const std::string& path) : path_(path), out_(path) {
  if (!out_) throw std::runtime_error(path + ": cannot open telemetry file for writing");
  out_.precision(9);
}

void CsvTelemetry::begin(const Model& model) {
  out_ << "time_s";
  for (int i = 0; i < model.robot().node_count(); ++i) {
    out_ << ",node" << i << "_x_m,node" << i << "_y_m,node" << i << "_z_m";
  }
  for (const char* what : {"rest_length_m", "length_m", "tension_n", "power_w"}) {
    for (int m = 0; m < model.cable_count(); ++m) out_ << ",cable" << m << "_" << what;
  }
  out_ << ",kinetic_energy_j,gravity_energy_j,elastic_energy_j\n";
}

void CsvTelemetry::record(double time_s, const Model& model) {
  out_ << time_s;
  for (const auto& p : model.node_positions()) out_ << ',' << p.x() << ',' << p.y() << ',' << p.z();
  for (const double v : model.rest_length_m()) out_ << ',' << v;
  for (const double v : model.length_m()) out_ << ',' << v;
  for (const double v : model.tension_n()) out_ << ',' << v;
  const auto tension = model.tension_n();
  const auto rate = model.rest_length_rate_m_per_s();
  for (int m = 0; m < model.cable_count(); ++m) out_ << ',' << tension[m] * rate[m];
  out_ << ',' << model.kinetic_energy_j() << ',' << model.gravity_energy_j() << ',' << model.elastic_energy_j() << '\n';
}

void CsvTelemetry::end() {
  out_.flush();
  if (!out_) throw std::runtime_error(path_ + ": writing telemetry failed");
}

}  // namespace tensegrity::sim
