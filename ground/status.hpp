// SPDX-License-Identifier: Apache-2.0
// What `tensegrity status` shows: one row per end cap from a Station snapshot.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "ground/station.hpp"

namespace tensegrity::ground {

const char* mode_name(std::uint8_t mode);
const char* fault_name(std::uint8_t fault);

// Fixed-width table of the end caps in `expected` (bit i: end cap i), one row
// each; `now_ns` (host clock) gives the heartbeat ages.
std::string format_status_table(const std::array<EndcapStatus, kEndcapCount>& status, std::int64_t now_ns,
                                std::uint16_t expected = kAllEndcaps);
// One JSON object {"endcaps":[...], "missing":[...]} with the same rows and the
// expected end caps that sent no heartbeat.
std::string format_status_json(const std::array<EndcapStatus, kEndcapCount>& status, std::int64_t now_ns,
                               std::uint16_t expected = kAllEndcaps);
// The end caps in `expected` that sent no heartbeat, in order.
std::vector<int> missing_endcaps(const std::array<EndcapStatus, kEndcapCount>& status, std::uint16_t expected);

}  // namespace tensegrity::ground
