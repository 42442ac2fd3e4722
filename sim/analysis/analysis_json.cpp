// SPDX-License-Identifier: Apache-2.0
#include "sim/analysis/analysis_json.hpp"

#include <algorithm>
#include <cmath>

namespace tensegrity::sim::analysis {
namespace {

namespace an = sim::analysis;
using nlohmann::json;

json groups_of(const std::vector<int>& labels, const std::vector<int>& leaf_order) {
  int count = 0;
  for (const int l : labels) count = std::max(count, l + 1);
  std::vector<std::vector<int>> groups(static_cast<std::size_t>(count));
  for (const int leaf : leaf_order)
    groups[static_cast<std::size_t>(labels[static_cast<std::size_t>(leaf)])].push_back(leaf);
  return groups;
}

json muscles_json(const an::Analysis& a, double window_start_s) {
  double rest_min = 1e9, rest_max = -1e9, mean_lo = 1e9, mean_hi = -1e9, tension = 0.0, peak = 0.0, power = 0.0;
  double power_lo = 1e9, power_hi = 0.0, stretch = 0.0;
  for (const auto& m : a.muscles) {
    rest_min = std::min(rest_min, m.rest_min_m);
    rest_max = std::max(rest_max, m.rest_max_m);
    mean_lo = std::min(mean_lo, m.rest_mean_m);
    mean_hi = std::max(mean_hi, m.rest_mean_m);
    tension += m.tension_mean_n / static_cast<double>(a.muscles.size());
    peak = std::max(peak, m.tension_max_n);
    power += m.power_mean_w / static_cast<double>(a.muscles.size());
    power_lo = std::min(power_lo, m.power_mean_w);
    power_hi = std::max(power_hi, m.power_mean_w);
    stretch += (m.length_mean_m - m.rest_mean_m) / static_cast<double>(a.muscles.size());
  }
  // Figure 11e's curve: the mean power per muscle, averaged over 1 s.
  std::vector<double> per_sample;
  for (const auto& r : a.robot) {
    if (r.time_s >= window_start_s) per_sample.push_back(r.power_mean_w);
  }
  const std::size_t width =
      per_sample.size() > 1
          ? static_cast<std::size_t>(
                std::lround(1.0 / ((a.window_end_s - a.window_start_s) / static_cast<double>(per_sample.size() - 1))))
          : 1;
  const auto smooth = an::moving_average(per_sample, width);
  const auto [lo, hi] = std::minmax_element(smooth.begin(), smooth.end());
  return {
      {"rest_length_m", {{"min", rest_min}, {"max", rest_max}, {"mean_lowest", mean_lo}, {"mean_highest", mean_hi}}},
      {"mean_stretch_m", stretch},
      {"tension_n", {{"mean", tension}, {"peak", peak}}},
      {"power_per_muscle_w",
       {{"mean", power},
        {"lowest_muscle", power_lo},
        {"highest_muscle", power_hi},
        {"mean_over_1s_min", smooth.empty() ? 0.0 : *lo},
        {"mean_over_1s_max", smooth.empty() ? 0.0 : *hi}}}};
}

json energy_json(const an::Analysis& a) {
  double ke_max = 0.0, ke_mean = 0.0, pe_min = 1e18, pe_max = 0.0;
  std::size_t n = 0;
  for (const auto& r : a.robot) {
    if (r.time_s < a.window_start_s) continue;
    ke_max = std::max(ke_max, r.kinetic_j);
    ke_mean += r.kinetic_j;
    pe_min = std::min(pe_min, r.elastic_j);
    pe_max = std::max(pe_max, r.elastic_j);
    ++n;
  }
  return {{"kinetic_mean_j", n ? ke_mean / static_cast<double>(n) : 0.0},
          {"kinetic_max_j", ke_max},
          {"elastic_min_j", pe_min},
          {"elastic_max_j", pe_max}};
}

json rolling_json(const an::Analysis& a) {
  json touched = json::array(), faces = json::array();
  for (std::size_t n = 0; n < a.contacts.spans.size(); ++n) {
    if (!a.contacts.spans[n].empty()) touched.push_back(n);
  }
  int closed = 0;
  for (const auto& f : a.faces) {
    faces.push_back(f.nodes);
    closed += f.closed ? 1 : 0;
  }
  return {{"endcaps_touched", touched},
          {"endcaps_touched_count", a.contacts.touched_count()},
          {"face_sequence", faces},
          {"faces_closed", closed},
          {"faces_per_cycle", a.cycle.faces},
          {"face_cycle_match", a.cycle.match},
          {"face_cycle_from_s", a.cycle.faces > 0 ? nlohmann::json(a.cycle.from_s) : nlohmann::json(nullptr)},
          {"revolutions", a.turning.revolutions()},
          {"turned_total_rad", a.turning.total_angle_rad},
          {"slip_m_per_s",
           {{"mean", a.slip.mean_m_per_s},
            {"median", a.slip.median_m_per_s},
            {"p95", a.slip.p95_m_per_s},
            {"samples", a.slip.samples}}}};
}

}  // namespace

json analysis_json(const an::EpisodeSeries& series, const an::Analysis& a, const an::AnalysisOptions& o) {
  json j = muscles_json(a, a.window_start_s);
  j["window_s"] = {a.window_start_s, a.window_end_s};
  j["samples"] = series.samples();
  j["endcaps"] = series.nodes();
  j["energy"] = energy_json(a);
  j["revolution_period_s"] = {{"contacts", a.contact_period.period_s},
                              {"contacts_agreement", a.contact_period.agreement},
                              {"faces", a.cycle.period_s},
                              {"rotation", a.rotation_period_s}};
  j["touchdown_interval_s"] = {{"median", a.touchdown_interval_s}, {"count", a.touchdown_intervals_s.size()}};
  j["rolling"] = rolling_json(a);
  double spin_max = 0.0;
  for (const double s : a.axial_spin_mean_rad_per_s) spin_max = std::max(spin_max, s);
  j["axial_spin_rad_per_s"] = {{"mean_per_strut", a.axial_spin_mean_rad_per_s}, {"largest_mean", spin_max}};
  j["clusters"] = {{"method", "average linkage on 1 - r"},
                   {"cut_height", o.cluster_cut},
                   {"zero_lag", groups_of(a.clusters, a.tree.leaf_order)},
                   {"phase_aligned", groups_of(a.aligned_clusters, a.aligned_tree.leaf_order)}};
  j["signal_peaks_per_period"] = a.peaks_per_period;
  return j;
}

}  // namespace tensegrity::sim::analysis
