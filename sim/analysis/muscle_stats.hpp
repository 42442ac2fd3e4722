// SPDX-License-Identifier: Apache-2.0
#pragma once
// Per-muscle summaries (Figures 10 and 11a/b/e) and the robot-wide time series
// (Figure 11a-e) of an episode.
#include <vector>

#include "sim/analysis/series.hpp"

namespace tensegrity::sim::analysis {

struct MuscleStats {
  int cable = 0;
  double rest_min_m = 0.0, rest_max_m = 0.0, rest_mean_m = 0.0;  // Figure 10
  double length_mean_m = 0.0;                                    // Figure 11a
  double tension_mean_n = 0.0, tension_max_n = 0.0;              // Figure 11b
  double power_mean_w = 0.0;                                     // Figure 11e
};

// Each cable over samples [first, end).
std::vector<MuscleStats> muscle_stats(const EpisodeSeries& series, std::size_t first);

// Per sample, over the cables: Figure 11a (mean rest and actual length), 11b (mean
// and largest tension), 11c (kinetic energy), 11d (elastic energy stored in the
// cables), 11e (mean motor power per cable).
struct RobotSample {
  double time_s = 0.0;
  double rest_mean_m = 0.0, length_mean_m = 0.0;
  double tension_mean_n = 0.0, tension_max_n = 0.0;
  double kinetic_j = 0.0, elastic_j = 0.0, gravity_j = 0.0;
  double power_mean_w = 0.0;
};
std::vector<RobotSample> robot_series(const EpisodeSeries& series);

// The mean of `values` over a centred window of `width` samples (shorter at the ends).
std::vector<double> moving_average(const std::vector<double>& values, std::size_t width);

}  // namespace tensegrity::sim::analysis
