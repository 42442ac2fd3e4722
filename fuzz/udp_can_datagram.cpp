// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: one datagram off an end cap's CAN-over-UDP bus (wire version 1,
// one frame, or version 2, a batch). Oracle beyond "no crash": every frame the
// decoder lets through is a valid CAN frame and encodes back to the same frame.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "firmware/hal/can_frame.hpp"
#include "firmware/hal/udp_can_batch.hpp"
#include "firmware/hal/udp_can_wire.hpp"

namespace udp_can = tensegrity::fw::udp_can;
using tensegrity::fw::CanFrame;

namespace {

void check_round_trip(const CanFrame& frame) {
  if (!tensegrity::fw::is_valid(frame)) std::abort();
  CanFrame again{};
  const udp_can::Datagram datagram = udp_can::encode(frame);
  if (udp_can::decode(datagram, again) != udp_can::Decoded::frame || !(again == frame)) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  CanFrame frame{};
  if (udp_can::decode(bytes, frame) == udp_can::Decoded::frame) check_round_trip(frame);

  const udp_can::DatagramReader reader(bytes);
  if (reader.status() != udp_can::Decoded::frame && reader.count() != 0) std::abort();
  if (reader.count() > udp_can::kMaxBatchFrames) std::abort();
  for (std::size_t i = 0; i < reader.count(); ++i) {
    CanFrame record{};
    if (reader.read(i, record) == udp_can::Decoded::frame) check_round_trip(record);
  }
  return 0;
}
