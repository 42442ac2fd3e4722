// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the page replays: frames at the display rate (end-cap positions, per cable
// rest length and tension, energies when recorded), from a telemetry CSV or from an
// episode run in-process (evolve_watch). Kept as floats: a 60 s run at 50 frames a
// second is 3000 frames, a few MB of JSON.
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "robot/robot.hpp"

namespace tensegrity::view {

// 50 frames a second: above the page's 30 fps target, and a 60 s run stays small.
inline constexpr double kFrameIntervalS = 0.02;
// Longer runs are thinned to this many frames so the page stays quick to open.
inline constexpr std::size_t kMaxFrames = 15000;

struct ReplayFrames {
  int nodes = 0;
  int cables = 0;
  bool has_energy = false;
  std::vector<double> time_s;
  std::vector<float> node_m;         // frames x nodes x 3
  std::vector<float> rest_length_m;  // frames x cables
  std::vector<float> tension_n;      // frames x cables
  std::vector<float> energy_j;       // frames x 3 (kinetic, gravitational, elastic) when has_energy
  std::size_t frames() const { return time_s.size(); }
};

// Collects frames no closer than `interval_s` in time.
class ReplayBuilder {
 public:
  ReplayBuilder(int nodes, int cables, bool has_energy, double interval_s = kFrameIntervalS);
  bool wants(double time_s) const { return frames_.time_s.empty() || time_s >= next_s_; }
  // `node_m`: nodes x 3; `energy_j`: 3 values, or empty without energy.
  void add(double time_s, std::span<const double> node_m, std::span<const double> rest_length_m,
           std::span<const double> tension_n, std::span<const double> energy_j);
  // Thinned to kMaxFrames if longer.
  ReplayFrames take();

 private:
  ReplayFrames frames_;
  double interval_s_;
  double next_s_ = 0.0;
};

// Reads a telemetry CSV of `tensegrity sim --telemetry` (node*_m, cable*_rest_length_m,
// cable*_tension_n, *_energy_j) or `tensegrity hil --record` (node*_m,
// rest_length_m_*, tension_n_*, *_energy_j) for `robot`. Throws InputError naming
// the file, line and column of anything missing or malformed. `warnings` gets the
// reader's (a dropped cut last line).
ReplayFrames load_replay_csv(const std::filesystem::path& path, const sim::Robot& robot,
                             std::vector<std::string>& warnings);

// The page's replay object: {"source", "frames", "time_s", "node_m", "rest_length_m",
// "tension_n", "energy_j" (or null), "centre_m", "distance_m"}; distance is the
// centre's horizontal distance from the first frame.
std::string replay_json(const ReplayFrames& frames, const std::string& source);

}  // namespace tensegrity::view
