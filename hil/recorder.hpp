// SPDX-License-Identifier: Apache-2.0
// Per-tick CSV of a HIL run: time, centre, per cable rest length and tension, every
// end cap's position and the energies, after each physics step. Buffered through
// one FILE*: a 60 s run is 60,000 rows.
#pragma once

#include <cstdio>
#include <filesystem>

#include "sim/model/model.hpp"

namespace tensegrity::hil {

class Recorder {
 public:
  // Throws HilError when the file cannot be created.
  Recorder(const std::filesystem::path& path, const sim::Model& model);
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;
  void record(double time_s, const sim::Model& model);
  // Flushes and closes; throws HilError on a write error (a full disk).
  void close();

 private:
  std::filesystem::path path_;
  std::FILE* file_ = nullptr;
};

}  // namespace tensegrity::hil
