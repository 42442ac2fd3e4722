// SPDX-License-Identifier: Apache-2.0
#include "ground/estops_seen.hpp"

#include <algorithm>

namespace tensegrity::ground {

void EstopsSeen::take_heard(const Station& station, std::uint16_t mask) {
  const auto status = station.snapshot();
  for (std::size_t e = 0; e < status.size(); ++e) {
    if ((mask & (1U << e)) == 0 || known[e] || !status[e].seen) continue;
    known[e] = true;
    count[e] = status[e].estops;
  }
}

bool EstopsSeen::all_known(std::uint16_t mask) const {
  for (std::size_t e = 0; e < known.size(); ++e) {
    if ((mask & (1U << e)) != 0 && !known[e]) return false;
  }
  return true;
}

void EstopsSeen::write_to(msg::Command_& cmd) const {
  std::array<std::uint32_t, kEndcapCount> lives{};
  std::array<std::uint32_t, kEndcapCount> counts{};
  for (std::size_t e = 0; e < known.size(); ++e) {
    if (!known[e]) continue;
    lives[e] = count[e].life_id;
    counts[e] = count[e].count;
  }
  cmd.lives_seen(lives);
  cmd.estops_seen(counts);
  cmd.asked_host_time_ns(asked_host_time_ns);
}

EstopsSeen estops_seen_now(const Station& station, std::uint16_t mask) {
  EstopsSeen seen = estops_asked_now();
  seen.take_heard(station, mask);
  return seen;
}

EstopsSeen estops_asked_now() {
  EstopsSeen seen;
  seen.asked_host_time_ns = Station::now_ns();
  return seen;
}

bool hear_unknown(const Station& station, std::uint16_t mask, std::int64_t until_ns, EstopsSeen& seen,
                  const std::function<bool()>& keep_going) {
  constexpr std::int64_t kSliceNs = 20'000'000;  // how soon a console's estop preempts the wait
  for (;;) {
    seen.take_heard(station, mask);
    if (seen.all_known(mask) || Station::now_ns() >= until_ns) return true;
    if (keep_going && !keep_going()) return false;
    station.wait_for_endcaps(mask, false, std::min(until_ns, Station::now_ns() + kSliceNs));
  }
}

}  // namespace tensegrity::ground
