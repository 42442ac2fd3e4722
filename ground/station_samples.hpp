// SPDX-License-Identifier: Apache-2.0
// What the station keeps of each sample an end cap writes, once the sample's writer
// has vouched for the end cap it names: pure, so the receive threads' listeners and
// the fuzzer run the same code. The listeners call these under the station's lock.
#pragma once

#include <cstdint>

#include "ground/station.hpp"

namespace tensegrity::ground {

enum class SampleVerdict : std::uint8_t {
  taken,
  wrong_format,  // another message-format version: counted in `refused` where the row keeps one
  stale_life,    // from a life the end cap has left: counted in `stale_life_samples`
};

bool valid_endcap(int id);
// False, and nothing kept, for a report of a life the end cap has left. Within a
// life the highest count wins; a new life replaces it and the old one is left.
bool merge_estops(EndcapStatus& e, const fw::comms::EstopCount& heard);

SampleVerdict take_heartbeat(EndcapStatus& e, const msg::Heartbeat_& hb, std::int64_t now_ns);
SampleVerdict take_telemetry(EndcapStatus& e, const msg::Telemetry_& t, std::int64_t now_ns);
// Acks are queued for the tool that waits for them; only their format is judged here.
SampleVerdict check_ack(std::uint16_t format_version);

}  // namespace tensegrity::ground
