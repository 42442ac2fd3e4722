// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: an evolution checkpoint (sim/evolve/checkpoint.hpp), as
// `tensegrity evolve --resume` reads checkpoint.json before it rebuilds the run.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "sim/evolve/checkpoint.hpp"

namespace evolve = tensegrity::sim::evolve;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const evolve::Checkpoint cp = evolve::parse_checkpoint(text, "fuzz");
    // A checkpoint the reader takes is one its writer could have written: saved
    // again it reads back the same.
    const std::string again = evolve::checkpoint_to_json(cp.config, cp.state);
    const evolve::Checkpoint back = evolve::parse_checkpoint(again, "fuzz written");
    if (evolve::checkpoint_to_json(back.config, back.state) != again) std::abort();
  } catch (const evolve::CheckpointError&) {
  }
  return 0;
}
