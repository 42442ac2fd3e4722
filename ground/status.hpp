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
// One JSON object {"endcaps":[...], "missing":[...], "silent":[...]} with the same
// rows (each with "heard": its heartbeat is recent) and the expected end caps that
// sent no heartbeat, or none lately.
std::string format_status_json(const std::array<EndcapStatus, kEndcapCount>& status, std::int64_t now_ns,
                               std::uint16_t expected = kAllEndcaps);
// The end caps in `expected` that sent no heartbeat, in order.
std::vector<int> missing_endcaps(const std::array<EndcapStatus, kEndcapCount>& status, std::uint16_t expected);
// The end caps in `expected` that were heard once but not for more than
// Station::kHeardFreshS: dead, cut off or hung. Their rows show the last state heard,
// marked SILENT, so a dead end cap never reads as a healthy one.
std::vector<int> silent_endcaps(const std::array<EndcapStatus, kEndcapCount>& status, std::int64_t now_ns,
                                std::uint16_t expected);

}  // namespace tensegrity::ground
