// SPDX-License-Identifier: Apache-2.0
// Stand-ins for the stepper's surroundings in unit tests: a clock that moves only
// when told (or when slept on), and end-cap programs that are flags.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "hil/clock.hpp"
#include "hil/endcap_roster.hpp"

namespace tensegrity::hil::hil_test {

class FakeClock final : public Clock {
 public:
  std::int64_t now_ns() const override { return now; }
  // Wakes at the deadline plus what `wake_late` says for this sleep (the host's
  // latency); a deadline already passed returns at once.
  void sleep_until(std::int64_t deadline_ns, std::int64_t) override {
    ++sleeps;
    if (deadline_ns <= now) return;
    now = deadline_ns + (wake_late ? wake_late(sleeps) : 0);
  }
  std::int64_t now = 1'000'000'000;
  int sleeps = 0;
  std::function<std::int64_t(int)> wake_late;
};

class FakeProcesses final : public EndcapProcesses {
 public:
  bool listening(int e) override {
    ++listening_checks;
    return listening_set.count(e) > 0;
  }
  bool exited(int e) override { return exited_set.count(e) > 0; }
  std::string describe(int e) override { return "fake " + std::to_string(e); }
  void kill(int e) override { killed.push_back(e); }
  void restart(int e) override { restarted.push_back(e); }
  std::string set_dds_link(int e, bool up) override {
    links.push_back({e, up});
    return no_link.count(e) ? "no DDS link" : "";
  }
  std::set<int> listening_set, exited_set, no_link;
  std::vector<int> killed, restarted;
  std::vector<std::pair<int, bool>> links;
  int listening_checks = 0;
};

}  // namespace tensegrity::hil::hil_test
