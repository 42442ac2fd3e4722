// SPDX-License-Identifier: Apache-2.0
// `hil --record`: the run as a run record (sim/model/run_record.hpp, the schema
// `sim --telemetry` writes), one row after each physics step; a 60 s run is 60,000 rows.
#pragma once

#include <filesystem>

#include "sim/model/model.hpp"
#include "sim/model/run_record.hpp"

namespace tensegrity::hil {

class Recorder {
 public:
  // Throws HilError when the file cannot be created.
  Recorder(const std::filesystem::path& path, const sim::Model& model);
  void record(double time_s, const sim::Model& model) { writer_.write_row(time_s, model); }
  // Flushes and closes; throws HilError on a write error (a full disk).
  void close();

 private:
  static sim::RunRecordWriter open(const std::filesystem::path& path, const sim::Model& model);
  sim::RunRecordWriter writer_;
};

}  // namespace tensegrity::hil
