// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: what a ground tool takes from the end caps, decoded as the
// station decodes it (ground/station_samples.hpp): a run of Telemetry_, Heartbeat_,
// CommandAck_ and PolicyAck_ samples into the station's per-end-cap rows, then the
// status table and JSON the console and `tensegrity status` print from them. Per
// sample: a type byte, a 16-bit length, the serialized payload. The writer is taken
// to vouch for the end cap the sample names when that is a valid id (the DDS
// writer's partition, which the fuzzer cannot forge, is checked before this).
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "cdr_sample.hpp"
#include "ground/station_samples.hpp"
#include "ground/status.hpp"
#include "tensegrity_msgs/msg/CommandAckPubSubTypes.h"
#include "tensegrity_msgs/msg/HeartbeatPubSubTypes.h"
#include "tensegrity_msgs/msg/PolicyAckPubSubTypes.h"
#include "tensegrity_msgs/msg/TelemetryPubSubTypes.h"

namespace ground = tensegrity::ground;
namespace msg = tensegrity_msgs::msg::dds_;
using tensegrity::fuzz::deserialize_sample;

namespace {

using Rows = std::array<ground::EndcapStatus, ground::kEndcapCount>;

ground::EndcapStatus* row(Rows& rows, int endcap) {
  return ground::valid_endcap(endcap) ? &rows[static_cast<std::size_t>(endcap)] : nullptr;
}

// Within one life the estop count a clear-fault will name never goes down.
void check_estops(const ground::EndcapStatus& before, const ground::EndcapStatus& after) {
  if (before.estops.life_id == after.estops.life_id && after.estops.count < before.estops.count) std::abort();
}

void take(Rows& rows, std::uint8_t type, const std::uint8_t* data, std::size_t size, std::int64_t now_ns) {
  switch (type % 4) {
    case 0: {
      msg::Telemetry_ t;
      if (!deserialize_sample<msg::Telemetry_PubSubType>(data, size, t)) return;
      if (ground::EndcapStatus* e = row(rows, t.endcap_id())) {
        const std::uint64_t count = e->telemetry_count;
        if (ground::take_telemetry(*e, t, now_ns) == ground::SampleVerdict::taken && e->telemetry_count != count + 1) {
          std::abort();
        }
      }
      return;
    }
    case 1: {
      msg::Heartbeat_ hb;
      if (!deserialize_sample<msg::Heartbeat_PubSubType>(data, size, hb)) return;
      if (ground::EndcapStatus* e = row(rows, hb.source())) {
        const ground::EndcapStatus before = *e;
        (void)ground::take_heartbeat(*e, hb, now_ns);
        check_estops(before, *e);
      }
      return;
    }
    case 2: {
      // A command ack carries the end cap's estop count after acting (ground/command.cpp).
      msg::CommandAck_ ack;
      if (!deserialize_sample<msg::CommandAck_PubSubType>(data, size, ack)) return;
      ground::EndcapStatus* e = row(rows, ack.endcap_id());
      if (e == nullptr || ground::check_ack(ack.format_version()) != ground::SampleVerdict::taken) return;
      const ground::EndcapStatus before = *e;
      (void)ground::merge_estops(*e, {ack.life_id(), ack.estops_received()});
      check_estops(before, *e);
      return;
    }
    default: {
      msg::PolicyAck_ ack;
      if (deserialize_sample<msg::PolicyAck_PubSubType>(data, size, ack)) (void)ground::check_ack(ack.format_version());
      return;
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Rows rows{};
  std::int64_t now_ns = 1'000'000'000;
  while (size >= 3) {
    const std::uint8_t type = data[0];
    std::uint16_t length = 0;
    std::memcpy(&length, data + 1, sizeof length);
    data += 3;
    size -= 3;
    const std::size_t n = length < size ? length : size;
    take(rows, type, data, n, now_ns);
    data += n;
    size -= n;
    now_ns += 10'000'000;
  }
  (void)ground::format_status_table(rows, now_ns);
  (void)ground::format_status_json(rows, now_ns);
  return 0;
}
