// SPDX-License-Identifier: Apache-2.0
#include "sim/analysis/analysis.hpp"

#include <cmath>
#include <stdexcept>

namespace tensegrity::sim::analysis {
namespace {

Matrix signals(const EpisodeSeries& s, std::size_t first, std::size_t end) {
  Matrix out;
  for (int m = 0; m < s.cables(); ++m) {
    auto column = s.column(s.rest_length_m, m, first);
    column.resize(end - first);
    out.push_back(std::move(column));
  }
  return out;
}

// The first sample of the last whole period: circular shifts are exact on it.
std::size_t last_period_start(const EpisodeSeries& s, double period_s) {
  const std::size_t n = s.samples();
  const double step = (s.time_s.back() - s.time_s.front()) / static_cast<double>(n - 1);
  const auto per = static_cast<std::size_t>(std::llround(period_s / step));
  return per >= 2 && per < n ? n - per : 0;
}

void rolling_evidence(const EpisodeSeries& s, std::size_t first, const std::vector<std::pair<int, int>>& cable_nodes,
                      const AnalysisOptions& o, Analysis& a) {
  a.contacts = detect_contacts(s.time_s, s.node_m, s.strut_radius_m, o.contacts);
  a.faces = face_sequence(s.time_s, a.contacts, cable_nodes, o.face_min_s);
  a.cycle = face_cycle(a.faces);
  a.touchdown_intervals_s = touchdown_intervals(a.contacts, a.window_start_s);
  a.touchdown_interval_s = a.touchdown_intervals_s.empty() ? 0.0 : quantile(a.touchdown_intervals_s, 0.5);
  // A revolution is longer than one signal period (the paper's is two); shorter
  // shifts only find the signal's own period.
  a.contact_period = contact_period(s.time_s, a.contacts, first, 0.5 * o.period_s);
  a.turning = accumulate_turning(s.node_m, first);
  const double revolutions = a.turning.revolutions();
  // Less than one whole turn measures no period; extrapolating a rock would invent one.
  a.rotation_period_s = revolutions >= 1.0 ? (a.window_end_s - a.window_start_s) / revolutions : 0.0;
  a.slip = summarize_slip(a.contacts, first + 1);
}

}  // namespace

Analysis analyze(const EpisodeSeries& s, const std::vector<std::pair<int, int>>& cable_nodes,
                 const AnalysisOptions& o) {
  if (s.samples() < 4) throw std::invalid_argument("analyze: the episode recorded fewer than 4 samples");
  if (!(o.period_s > 0.0)) throw std::invalid_argument("analyze: period_s must be positive");
  Analysis a;
  // Leave out the first period when at least one more follows it.
  const double skip = s.time_s.back() >= 2.0 * o.period_s ? o.period_s : 0.0;
  std::size_t first = std::min(s.first_at(skip), s.samples() - 3);
  a.window_start_s = s.time_s[first];
  a.window_end_s = s.time_s.back();
  a.muscles = muscle_stats(s, first);
  a.robot = robot_series(s);

  a.correlation = correlation_matrix(signals(s, first, s.samples()));
  a.tree = average_linkage(one_minus(a.correlation));
  a.clusters = cut(a.tree, o.cluster_cut);
  const std::size_t period_first = std::max(first, last_period_start(s, o.period_s));
  const Matrix last_period = signals(s, period_first, s.samples());
  a.aligned = aligned_correlation_matrix(last_period);
  // 2 cm: well above the motors' 0.2 mm step at 1 kHz, a fifth of the smallest
  // interval a learned signal spans.
  for (const auto& signal : last_period) a.peaks_per_period.push_back(peaks_per_period(signal, 0.02));
  a.aligned_tree = average_linkage(one_minus(a.aligned.r));
  a.aligned_clusters = cut(a.aligned_tree, o.cluster_cut);

  rolling_evidence(s, first, cable_nodes, o, a);
  const std::size_t struts = s.axial_spin_rad_per_s.empty() ? 0 : s.axial_spin_rad_per_s.front().size();
  a.axial_spin_mean_rad_per_s.assign(struts, 0.0);
  for (std::size_t k = first; k < s.samples(); ++k) {
    for (std::size_t j = 0; j < struts; ++j) {
      a.axial_spin_mean_rad_per_s[j] += s.axial_spin_rad_per_s[k][j] / static_cast<double>(s.samples() - first);
    }
  }
  return a;
}

}  // namespace tensegrity::sim::analysis
