// SPDX-License-Identifier: Apache-2.0
// After a start's acks: are the end caps playing? An ack says the end cap took the
// order; the control loop may still not play it (a fault latched, a drive that
// dropped out between the ack and the start time). Telemetry sent after the start
// time says what happened, so `tensegrity start` does not report success for an end
// cap that stayed idle.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "ground/station.hpp"

namespace tensegrity::ground {

struct PlayingCheck {
  int endcap = 0;
  bool playing = false;
  bool heard = false;  // telemetry sampled at or after the start time arrived
  std::string state;   // what that telemetry said, for the report ("idle, fault drive_lost, drives not enabled")
};

// One entry per end cap in `mask`, in order: playing when its newest telemetry was
// sampled at or after `start_ns` (its own host-time stamp, Telemetry_::host_time_ns:
// a sample of an end cap already running, sent before the start and arriving after
// it, says nothing about the start) and shows it running.
std::vector<PlayingCheck> check_playing(const std::array<EndcapStatus, kEndcapCount>& status, std::uint16_t mask,
                                        std::int64_t start_ns);

// Polls the station until every end cap in `mask` plays or `deadline_ns` passes.
std::vector<PlayingCheck> wait_playing(const Station& station, std::uint16_t mask, std::int64_t start_ns,
                                       std::int64_t deadline_ns);

bool all_playing(const std::vector<PlayingCheck>& checks);
// "12 of 12 end caps playing", then one line per end cap that is not.
std::string format_playing(const std::vector<PlayingCheck>& checks);

}  // namespace tensegrity::ground
