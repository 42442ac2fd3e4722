// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: what the end cap's node takes from the host besides commands
// and tables. First byte even: one host Heartbeat_ (the node reads its format
// version and heard_endcaps). Odd: a run of events into the time-sync client the
// node keeps (time_sync_client.hpp): requests sent, TimeSyncReply_ samples decoded
// as the node decodes them and handed on with their arrival time, settling; a
// reply may be steered to echo an outstanding request's nonce, which a mutation
// would almost never guess, so the estimator behind the checks is reached.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "cdr_sample.hpp"
#include "fuzz_input.hpp"
#include "firmware/comms/logic/time_sync_client.hpp"
#include "msgs/format_version.hpp"
#include "tensegrity_msgs/msg/HeartbeatPubSubTypes.h"
#include "tensegrity_msgs/msg/TimeSyncPubSubTypes.h"

namespace comms = tensegrity::fw::comms;
namespace m = tensegrity_msgs::msg::dds_;

namespace {

using tensegrity::fuzz::Input;

constexpr std::int16_t kEndcap = 3;

void run_time_sync(Input in) {
  const comms::TimeSyncLimits limits;
  comms::TimeSyncClient client(0x5eed, limits);
  std::array<std::uint64_t, comms::TimeSyncClient::kOutstanding> nonces{};
  std::size_t sent = 0;
  std::int64_t now = 1'000'000'000;
  while (in.left > 0) {
    const auto op = in.take<std::uint8_t>();
    now += in.take<std::uint16_t>() * 1'000;  // time only moves forward, as the node's clock does
    switch (op & 3U) {                        // bits 2-4: which outstanding nonce a steered reply echoes
      case 0: nonces[sent++ % nonces.size()] = client.start_request(now); break;
      case 1: {
        const std::size_t length = in.take<std::uint8_t>();
        const std::size_t n = length < in.left ? length : in.left;
        m::TimeSyncReply_ reply;
        const bool decoded = tensegrity::fuzz::deserialize_sample<m::TimeSyncReply_PubSubType>(in.at, n, reply);
        in.at += n;
        in.left -= n;
        if (!decoded || reply.endcap_id() != kEndcap || reply.format_version() != tensegrity::msgs::kFormatVersion) {
          break;  // the node drops these before the client
        }
        const std::uint64_t nonce = (op & 0x80U) != 0 ? nonces[(op >> 2U) % nonces.size()] : reply.nonce();
        (void)client.on_reply(nonce, reply.t2_ns(), reply.t3_ns(), now);
        break;
      }
      default: client.settle(now); break;
    }
    // Whatever the replies said, an estimate in use came from a plausible round trip.
    if (client.estimator().synced()) {
      const comms::ClockSample best = client.estimator().best();
      if (best.round_trip_ns < 0 || best.round_trip_ns > limits.max_round_trip_ns) std::abort();
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  if ((data[0] & 1U) == 0) {
    m::Heartbeat_ hb;
    if (tensegrity::fuzz::deserialize_sample<m::Heartbeat_PubSubType>(data + 1, size - 1, hb) &&
        hb.format_version() == tensegrity::msgs::kFormatVersion) {
      (void)hb.heard_endcaps();
    }
    return 0;
  }
  run_time_sync(Input{data + 1, size - 1});
  return 0;
}
