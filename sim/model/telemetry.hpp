// SPDX-License-Identifier: Apache-2.0
#pragma once
// Per-step telemetry of an episode, on request: a sink sees the model after each
// recorded step.
#include <memory>
#include <string>

#include "sim/model/run_record.hpp"

namespace tensegrity::sim {

class Model;

class TelemetrySink {
 public:
  virtual ~TelemetrySink() = default;
  virtual void begin(const Model& model) = 0;
  virtual void record(double time_s, const Model& model) = 0;
  virtual void end() {}
};

// `sim --telemetry`: the episode as a run record (sim/model/run_record.hpp), one row
// per recorded step. The file is created at construction, so a bad path fails before
// the episode runs.
class CsvTelemetry final : public TelemetrySink {
 public:
  explicit CsvTelemetry(const std::string& path);
  void begin(const Model& model) override;
  void record(double time_s, const Model& model) override;
  void end() override;

 private:
  std::string path_;
  std::unique_ptr<RunRecordWriter> writer_;
};

}  // namespace tensegrity::sim
