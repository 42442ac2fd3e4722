// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: one MPI message from another rank (sim/evolve/mpi_wire.hpp).
// The first byte is the tag, as the receiving rank reads it off the envelope; the
// rest are the message's bytes. A setup is read on to the episode it describes,
// as an evaluating rank does before it builds its scorer.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "sim/evolve/episode_setup.hpp"
#include "sim/evolve/mpi_wire.hpp"

namespace evolve = tensegrity::sim::evolve;
namespace wire = tensegrity::sim::evolve::wire;

namespace {
// What decodes must encode back to the very bytes: the format has one spelling.
template <typename Message>
void same_bytes(const Message& m, const wire::Bytes& bytes) {
  if (wire::encode(m) != bytes) std::abort();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const wire::Bytes bytes(data + 1, data + size);
  try {
    switch (data[0] % 4) {
      case 0: {
        const wire::Setup setup = wire::decode_setup(bytes);
        same_bytes(setup, bytes);
        (void)evolve::episode_setup_from_wire(setup);
        break;
      }
      case 1: same_bytes(wire::decode_hello(bytes), bytes); break;
      case 2: same_bytes(wire::decode_job(bytes), bytes); break;
      default: same_bytes(wire::decode_result(bytes), bytes); break;
    }
  } catch (const wire::WireError&) {
  }
  return 0;
}
