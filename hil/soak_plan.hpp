// SPDX-License-Identifier: Apache-2.0
// The chaos soak's scenario (tensegrity soak): seeded random end-cap kills and
// restarts, link cuts (one end cap or the host's), drive reboots and an operator's
// estops, clears and starts, as ordinary scenario events (scenario.hpp) for the
// fault injector. Also what the soak's checks need to know of it: which end caps an
// estop at a given time must reach, and how many host losses the cuts explain.
#pragma once

#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "hil/scenario.hpp"

namespace tensegrity::hil {

struct SoakPlanOptions {
  std::uint64_t seed = 1;
  double duration_s = 120.0;
  std::vector<int> motors;     // per end cap: how many drives it has (its size is the end-cap count)
  double quiet_start_s = 8.0;  // no event before (all twelve playing first)
  double quiet_end_s = 8.0;    // none in the last seconds (every restart and restore done)
  double mean_gap_s = 5.0;     // mean time between episodes (exponential)
  double settle_s = 15.0;      // after a restart or restore: the end cap is on the link again
};

// One episode's kind, drawn with fixed weights.
enum class SoakEpisode : std::uint8_t { kill_restart, cut_one, cut_all, reboot_drive, estop };

// Throws HilError naming the field for options it cannot plan (no end caps, a
// duration shorter than the quiet times).
Scenario make_soak_scenario(const SoakPlanOptions& options);
// The scenario as a tensegrity-hil-scenario/1 file (`tensegrity hil --scenario`) of
// the events the soak makes (no parameters but a drive reboot's motor).
nlohmann::json scenario_json(const Scenario& scenario);

// What the scenario did to each end cap by physics time `t_s`.
class SoakTimeline {
 public:
  SoakTimeline(const Scenario& scenario, int endcap_count, double settle_s);
  // Running, its link up, and neither (re)started nor restored within settle_s:
  // an estop at `t_s` must reach it.
  bool must_reach(int endcap, double t_s) const;
  // Cuts of the end cap's link (its own or the host's): each may cost one host
  // loss, nothing else may.
  int cuts_of(int endcap) const;

 private:
  struct Window {
    double from_s, to_s;  // down (killed or cut) from .. to, then settling to to_s + settle
    bool cut;
  };
  std::vector<std::vector<Window>> down_;  // per end cap
  double settle_s_;
};

}  // namespace tensegrity::hil
