// SPDX-License-Identifier: Apache-2.0
// What a clear-fault says it has seen: each addressed end cap's emergency stops
// (its life id and count) as the tool had heard them when the operator asked, and
// when that was. An end cap that took another estop since, or one issued after the
// asking, refuses the clear (firmware/comms/logic/command_gate.hpp, rule 7), so a clear
// held up on the link, queued behind another command, or sent by a tool that first
// heard the end cap after another tool's estop, cannot undo an estop sent after it.
#pragma once

#include <array>
#include <cstdint>
#include <functional>

#include "firmware/comms/wire/estop_count.hpp"
#include "ground/station.hpp"

namespace tensegrity::ground {

struct EstopsSeen {
  std::array<bool, kEndcapCount> known{};
  std::array<fw::comms::EstopCount, kEndcapCount> count{};
  std::int64_t asked_host_time_ns = 0;  // Station::now_ns() when the operator asked

  // Takes the count of each end cap in `mask` heard by `station` and not yet known;
  // a known one keeps the count it was first heard with.
  void take_heard(const Station& station, std::uint16_t mask);
  bool all_known(std::uint16_t mask) const;
  // Command_::lives_seen, estops_seen (an unknown end cap: zeros, which no life
  // matches, so it refuses the clear) and asked_host_time_ns.
  void write_to(msg::Command_& cmd) const;
};

// The operator's view at the moment of asking.
EstopsSeen estops_seen_now(const Station& station, std::uint16_t mask);
// The moment of asking, before the tool has heard any end cap: the end caps are
// filled in as they are first heard (hear_unknown), and an estop issued since
// still refuses the clear.
EstopsSeen estops_asked_now();

// Until every end cap in `mask` is known or `until_ns` (host clock), taking each
// count the first time the end cap is heard. False when `keep_going` (if set) ended
// the wait: an operator console's estop must not queue behind a clear-fault.
bool hear_unknown(const Station& station, std::uint16_t mask, std::int64_t until_ns, EstopsSeen& seen,
                  const std::function<bool()>& keep_going);

}  // namespace tensegrity::ground
