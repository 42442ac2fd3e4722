// SPDX-License-Identifier: Apache-2.0
#pragma once
// Everything `tensegrity analyze` reports of one episode (Figures 10-12 of Iscen et
// al. and the rolling evidence), computed from an EpisodeSeries.
#include <utility>
#include <vector>

#include "sim/analysis/clustering.hpp"
#include "sim/analysis/contacts.hpp"
#include "sim/analysis/correlation.hpp"
#include "sim/analysis/faces.hpp"
#include "sim/analysis/muscle_stats.hpp"
#include "sim/analysis/rotation.hpp"
#include "sim/analysis/series.hpp"
#include "sim/analysis/signal_shape.hpp"

namespace tensegrity::sim::analysis {

struct AnalysisOptions {
  // The policy's period: the signals repeat with it; the first one is the motors'
  // approach from the start lengths, so the per-muscle figures leave it out.
  double period_s = 4.0;
  ContactOptions contacts;
  double face_min_s = 0.1;  // a ground face must hold this long to count
  // Flat clusters: groups whose members' mean r is at least 1 - cluster_cut.
  double cluster_cut = 0.5;
};

struct Analysis {
  double window_start_s = 0.0;  // per-muscle figures, correlation, slip, turning
  double window_end_s = 0.0;
  std::vector<MuscleStats> muscles;
  std::vector<RobotSample> robot;
  // Figure 12: zero-lag r of the rest-length signals, clustered on 1 - r...
  Matrix correlation;
  Dendrogram tree;
  std::vector<int> clusters;
  // ...and, as the paper's lower panel does, with each pair shifted to its best lag
  // over the last whole period (same shapes, any phase).
  AlignedMatrix aligned;
  Dendrogram aligned_tree;
  std::vector<int> aligned_clusters;
  // Per cable: peaks of its rest length in the last period (prominence 2 cm).
  std::vector<int> peaks_per_period;
  // Rolling evidence.
  Contacts contacts;
  std::vector<GroundFace> faces;
  FaceCycle cycle;
  std::vector<double> touchdown_intervals_s;
  double touchdown_interval_s = 0.0;  // median of the intervals; 0 without any
  ContactPeriod contact_period;       // the revolution, from every end cap's contacts
  Turning turning;
  double rotation_period_s = 0.0;  // window length / revolutions; 0 below one revolution
  SlipSummary slip;
  std::vector<double> axial_spin_mean_rad_per_s;  // per strut, over the window
};

// `cable_nodes`: each cable's two end caps (for closed faces).
Analysis analyze(const EpisodeSeries& series, const std::vector<std::pair<int, int>>& cable_nodes,
                 const AnalysisOptions& options);

}  // namespace tensegrity::sim::analysis
