// SPDX-License-Identifier: Apache-2.0
// What `tensegrity status` shows: one row per end cap from a Station snapshot.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "ground/station.hpp"

namespace tensegrity::ground {

const char* mode_name(std::uint8_t mode);
const char* fault_name(std::uint8_t fault);

// Fixed-width table; `now_ns` (host clock) gives the heartbeat ages.
std::string format_status_table(const std::array<EndcapStatus, kEndcapCount>& status, std::int64_t now_ns);
// One JSON object {"endcaps":[...]} with the same fields.
std::string format_status_json(const std::array<EndcapStatus, kEndcapCount>& status, std::int64_t now_ns);

}  // namespace tensegrity::ground
