// SPDX-License-Identifier: Apache-2.0
#pragma once
// Per-step telemetry of an episode, on request: a sink sees the model after each
// recorded step.
#include <fstream>
#include <string>

namespace tensegrity::sim {

class Model;

class TelemetrySink {
 public:
  virtual ~TelemetrySink() = default;
  virtual void begin(const Model& model) = 0;
  virtual void record(double time_s, const Model& model) = 0;
  virtual void end() {}
};

// One CSV row per recorded step: time; every node's position; per cable rest
// length, length, tension and motor power (tension x rest-length rate); kinetic,
// gravitational and elastic energy.
class CsvTelemetry final : public TelemetrySink {
 public:
  explicit CsvTelemetry(const std::string& path);
  void begin(const Model& model) override;
  void record(double time_s, const Model& model) override;
  void end() override;

 private:
  std::string path_;
  std::ofstream out_;
};

}  // namespace tensegrity::sim
