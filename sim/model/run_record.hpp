// SPDX-License-Identifier: Apache-2.0
#pragma once
// The run record: one CSV schema that `sim --telemetry` and `hil --record` write and
// the view and tools/ read (docs/reference/files.md, "Run record"). A row is the model
// after a step: time; the end caps' centre; every end cap's position; per cable its
// rest length, length, tension and motor power (tension x rest-length rate); the
// kinetic, gravitational and elastic energy.
//
// Rows are formatted with std::to_chars into one buffer sized at open, so that writing
// a row allocates nothing: the HIL writes one after every physics step of its loop.
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace tensegrity::sim {

class Model;

// A run record names one cable's quantity cableM_QUANTITY: cable_column(3, "tension_n")
// is "cable3_tension_n".
std::string cable_column(int cable, std::string_view quantity);
// The name HIL records of older versions used, QUANTITY_M ("tension_n_3"): readers
// accept it too, so a record made then stays readable.
std::string legacy_cable_column(int cable, std::string_view quantity);

// The header of a run record of `model`'s robot, without the line end.
std::string run_record_header(const Model& model);

class RunRecordWriter {
 public:
  // Creates the file and writes the header; throws std::runtime_error naming the path
  // when it cannot.
  RunRecordWriter(const std::string& path, const Model& model);
  ~RunRecordWriter();
  RunRecordWriter(const RunRecordWriter&) = delete;
  RunRecordWriter& operator=(const RunRecordWriter&) = delete;

  void write_row(double time_s, const Model& model);
  // Flushes and closes; throws std::runtime_error naming the path on a write error
  // (a full disk). Closing twice is harmless.
  void close();

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
  std::vector<char> row_;
};

}  // namespace tensegrity::sim
