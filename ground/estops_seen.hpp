// SPDX-License-Identifier: Apache-2.0
// What a clear-fault says it has seen: each addressed end cap's emergency stops
// (its life id and count) as the tool had heard them when the operator asked. An
// end cap that took another estop since refuses the clear (firmware/comms/
// command_gate.hpp, rule 7), so a clear held up on the link, or queued behind
// another command, cannot undo an estop someone sent after it.
#pragma once

#include <array>
#include <cstdint>
#include <functional>

#include "firmware/comms/estop_count.hpp"
#include "ground/station.hpp"

namespace tensegrity::ground {

struct EstopsSeen {
  std::array<bool, kEndcapCount> known{};
  std::array<fw::comms::EstopCount, kEndcapCount> count{};

  // Takes the count of each end cap in `mask` heard by `station` and not yet known;
  // a known one keeps the count it was first heard with.
  void take_heard(const Station& station, std::uint16_t mask);
  bool all_known(std::uint16_t mask) const;
  // Command_::lives_seen and estops_seen (an unknown end cap: zeros, which no life
  // matches, so it refuses the clear).
  void write_to(msg::Command_& cmd) const;
};

// The operator's view at the moment of asking.
EstopsSeen estops_seen_now(const Station& station, std::uint16_t mask);

// Until every end cap in `mask` is known or `until_ns` (host clock), taking each
// count the first time the end cap is heard. False when `keep_going` (if set) ended
// the wait: an operator console's estop must not queue behind a clear-fault.
bool hear_unknown(const Station& station, std::uint16_t mask, std::int64_t until_ns, EstopsSeen& seen,
                  const std::function<bool()>& keep_going);

}  // namespace tensegrity::ground
