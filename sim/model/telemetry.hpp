// SPDX-License-Identifier: Apache-2.0
#pragma once
// Per-step telemetry of an episode, on request: a sink sees the model after each
// recorded step.
#include <fstream>
#include <string>
#include <string_view>

namespace tensegrity::sim {

class Model;

// A run record (`sim --telemetry`, `hil --record`) names one cable's quantity
// cableM_QUANTITY: cable_column(3, "tension_n") is "cable3_tension_n". Both writers
// use it, so the view and the tools read either record by the same names.
std::string cable_column(int cable, std::string_view quantity);
// The name HIL records of older versions used, QUANTITY_M ("tension_n_3"): readers
// accept it too, so a record made then stays readable.
std::string legacy_cable_column(int cable, std::string_view quantity);

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
