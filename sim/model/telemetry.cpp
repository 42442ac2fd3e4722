// SPDX-License-Identifier: Apache-2.0
#include "sim/model/telemetry.hpp"

#include <fstream>
#include <stdexcept>

namespace tensegrity::sim {

CsvTelemetry::CsvTelemetry(const std::string& path) : path_(path) {
  if (!std::ofstream(path)) throw std::runtime_error(path + ": cannot open telemetry file for writing");
}

void CsvTelemetry::begin(const Model& model) { writer_ = std::make_unique<RunRecordWriter>(path_, model); }

void CsvTelemetry::record(double time_s, const Model& model) {
  if (writer_ == nullptr) throw std::logic_error("CsvTelemetry::record before begin");
  writer_->write_row(time_s, model);
}

void CsvTelemetry::end() {
  if (writer_ != nullptr) writer_->close();
}

}  // namespace tensegrity::sim
