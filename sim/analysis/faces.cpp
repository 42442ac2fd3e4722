// SPDX-License-Identifier: Apache-2.0
#include "sim/analysis/faces.hpp"

#include <algorithm>

namespace tensegrity::sim::analysis {
namespace {

bool is_cable(const std::vector<std::pair<int, int>>& cables, int a, int b) {
  return std::any_of(cables.begin(), cables.end(),
                     [&](const auto& c) { return (c.first == a && c.second == b) || (c.first == b && c.second == a); });
}

// The three touching end caps of a sample, or {-1,-1,-1} unless exactly three touch.
std::array<int, 3> triangle_of(const std::vector<bool>& touching) {
  std::array<int, 3> out{-1, -1, -1};
  int n = 0;
  for (std::size_t i = 0; i < touching.size(); ++i) {
    if (!touching[i]) continue;
    if (n == 3) return {-1, -1, -1};
    out[static_cast<std::size_t>(n++)] = static_cast<int>(i);
  }
  return n == 3 ? out : std::array<int, 3>{-1, -1, -1};
}

}  // namespace

std::vector<GroundFace> face_sequence(const std::vector<double>& time_s, const Contacts& contacts,
                                      const std::vector<std::pair<int, int>>& cable_nodes, double min_duration_s) {
  std::vector<GroundFace> out;
  GroundFace run;
  bool in_run = false;
  auto close_run = [&] {
    if (!in_run || run.end_s - run.start_s < min_duration_s) return;
    if (!out.empty() && out.back().nodes == run.nodes) {
      out.back().end_s = run.end_s;
      return;
    }
    const auto& v = run.nodes;
    run.closed =
        is_cable(cable_nodes, v[0], v[1]) && is_cable(cable_nodes, v[1], v[2]) && is_cable(cable_nodes, v[0], v[2]);
    out.push_back(run);
  };
  for (std::size_t k = 0; k < time_s.size(); ++k) {
    const auto tri = triangle_of(contacts.touching[k]);
    if (in_run && tri == run.nodes) {
      run.end_s = time_s[k];
      continue;
    }
    close_run();
    in_run = tri[0] >= 0;
    if (in_run) run = GroundFace{tri, time_s[k], time_s[k], false};
  }
  close_run();
  return out;
}

namespace {
// How well faces[from..] repeats with a cycle of `len` faces.
FaceCycle cycle_stats(const std::vector<GroundFace>& faces, int from, int len) {
  const int n = static_cast<int>(faces.size());
  int same = 0;
  double span = 0.0;
  for (int i = from; i + len < n; ++i) {
    const auto& a = faces[static_cast<std::size_t>(i)];
    const auto& b = faces[static_cast<std::size_t>(i + len)];
    if (a.nodes != b.nodes) continue;
    ++same;
    span += b.start_s - a.start_s;
  }
  const double match = static_cast<double>(same) / static_cast<double>(n - from - len);
  return {len, same > 0 ? span / same : 0.0, match, from, faces[static_cast<std::size_t>(from)].start_s};
}
}  // namespace

FaceCycle face_cycle(const std::vector<GroundFace>& faces, double min_match, double max_settle_share) {
  const int n = static_cast<int>(faces.size());
  const auto last_start = static_cast<int>(max_settle_share * static_cast<double>(n));
  for (int from = 0; from <= last_start; ++from) {
    for (int len = 2; from + 2 * len <= n; ++len) {
      if (cycle_stats(faces, from, len).match < min_match) continue;
      // Settled from the first face that the next cycle repeats.
      int settled = from;
      while (settled + 2 * len < n &&
             faces[static_cast<std::size_t>(settled)].nodes != faces[static_cast<std::size_t>(settled + len)].nodes) {
        ++settled;
      }
      return cycle_stats(faces, settled, len);
    }
  }
  return {};
}

}  // namespace tensegrity::sim::analysis
