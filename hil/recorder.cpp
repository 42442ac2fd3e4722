// SPDX-License-Identifier: Apache-2.0
#include "hil/recorder.hpp"

#include <stdexcept>

#include "hil/hil_error.hpp"

namespace tensegrity::hil {

sim::RunRecordWriter Recorder::open(const std::filesystem::path& path, const sim::Model& model) {
  try {
    return sim::RunRecordWriter(path.string(), model);
  } catch (const std::runtime_error& e) {
    throw HilError(e.what());
  }
}

Recorder::Recorder(const std::filesystem::path& path, const sim::Model& model) : writer_(open(path, model)) {}

void Recorder::close() {
  try {
    writer_.close();
  } catch (const std::runtime_error& e) {
    throw HilError(e.what());
  }
}

}  // namespace tensegrity::hil
