// SPDX-License-Identifier: Apache-2.0
#include "hil/recorder.hpp"

#include "hil/hil_error.hpp"
#include "sim/model/telemetry.hpp"

namespace tensegrity::hil {

Recorder::Recorder(const std::filesystem::path& path, const sim::Model& model) : path_(path) {
  file_ = std::fopen(path.c_str(), "w");
  if (file_ == nullptr) throw HilError(path.string() + ": cannot create the record file");
  std::fputs("time_s,centre_x_m,centre_y_m,centre_z_m", file_);
  // Every column named as in `tensegrity sim --telemetry` (cableM_tension_n, nodeI_x_m,
  // the energies): the view and tools/ read both records alike.
  for (const char* what : {"rest_length_m", "tension_n"}) {
    for (int c = 0; c < model.cable_count(); ++c) std::fprintf(file_, ",%s", sim::cable_column(c, what).c_str());
  }
  for (int i = 0; i < model.robot().node_count(); ++i)
    std::fprintf(file_, ",node%d_x_m,node%d_y_m,node%d_z_m", i, i, i);
  std::fputs(",kinetic_energy_j,gravity_energy_j,elastic_energy_j", file_);
  std::fputc('\n', file_);
}

Recorder::~Recorder() {
  if (file_ != nullptr) std::fclose(file_);
}

void Recorder::record(double time_s, const sim::Model& model) {
  const auto centre = model.centre_m();
  std::fprintf(file_, "%.3f,%.6f,%.6f,%.6f", time_s, centre.x(), centre.y(), centre.z());
  for (double r : model.rest_length_m()) std::fprintf(file_, ",%.6f", r);
  for (double t : model.tension_n()) std::fprintf(file_, ",%.3f", t);
  for (const auto& p : model.node_positions()) std::fprintf(file_, ",%.5f,%.5f,%.5f", p.x(), p.y(), p.z());
  std::fprintf(file_, ",%.4f,%.4f,%.4f", model.kinetic_energy_j(), model.gravity_energy_j(), model.elastic_energy_j());
  std::fputc('\n', file_);
}

void Recorder::close() {
  if (file_ == nullptr) return;
  const bool bad = std::ferror(file_) != 0;
  const bool close_failed = std::fclose(file_) != 0;
  file_ = nullptr;
  if (bad || close_failed) throw HilError(path_.string() + ": write error");
}

}  // namespace tensegrity::hil
