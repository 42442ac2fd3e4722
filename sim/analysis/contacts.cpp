// SPDX-License-Identifier: Apache-2.0
#include "sim/analysis/contacts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace tensegrity::sim::analysis {
namespace {

// Raw runs of contact of one end cap, joined across gaps shorter than `debounce_s`.
std::vector<ContactInterval> spans_of(const std::vector<double>& time_s, const std::vector<std::vector<bool>>& touching,
                                      std::size_t node, double debounce_s) {
  std::vector<ContactInterval> out;
  bool in = false;
  for (std::size_t k = 0; k < time_s.size(); ++k) {
    const bool now = touching[k][node];
    if (now && !in) {
      if (!out.empty() && time_s[k] - out.back().end_s < debounce_s) {
        in = true;  // the same contact, resumed
      } else {
        out.push_back({time_s[k], time_s[k]});
        in = true;
      }
    }
    if (now) out.back().end_s = time_s[k];
    if (!now) in = false;
  }
  return out;
}

}  // namespace

std::vector<bool> Contacts::touched() const {
  std::vector<bool> out;
  for (const auto& s : spans) out.push_back(!s.empty());
  return out;
}

int Contacts::touched_count() const {
  int n = 0;
  for (const auto& s : spans) n += s.empty() ? 0 : 1;
  return n;
}

Contacts detect_contacts(const std::vector<double>& time_s, const std::vector<std::vector<Eigen::Vector3d>>& node_m,
                         double endcap_radius_m, const ContactOptions& options) {
  if (time_s.size() != node_m.size())
    throw std::invalid_argument("detect_contacts: times and positions differ in count");
  Contacts c;
  const std::size_t nodes = node_m.empty() ? 0 : node_m.front().size();
  c.share.assign(nodes, 0.0);
  for (std::size_t k = 0; k < time_s.size(); ++k) {
    std::vector<bool> row(nodes, false);
    std::vector<double> slip(nodes, -1.0);
    for (std::size_t n = 0; n < nodes; ++n) {
      row[n] = node_m[k][n].z() - endcap_radius_m <= options.tolerance_m;
      if (row[n]) c.share[n] += 1.0 / static_cast<double>(time_s.size());
      const double dt = k > 0 ? time_s[k] - time_s[k - 1] : 0.0;
      if (row[n] && k > 0 && c.touching[k - 1][n] && dt > 0.0) {
        slip[n] = (node_m[k][n] - node_m[k - 1][n]).head<2>().norm() / dt;
      }
    }
    c.touching.push_back(std::move(row));
    c.slip_m_per_s.push_back(std::move(slip));
  }
  for (std::size_t n = 0; n < nodes; ++n) c.spans.push_back(spans_of(time_s, c.touching, n, options.debounce_s));
  return c;
}

std::vector<double> touchdown_intervals(const Contacts& contacts, double from_s) {
  std::vector<double> out;
  for (const auto& spans : contacts.spans) {
    double last = std::numeric_limits<double>::quiet_NaN();
    for (const auto& s : spans) {
      if (s.start_s < from_s) continue;
      if (!std::isnan(last)) out.push_back(s.start_s - last);
      last = s.start_s;
    }
  }
  return out;
}

ContactPeriod contact_period(const std::vector<double>& time_s, const Contacts& contacts, std::size_t first,
                             double min_s, double slack) {
  const std::size_t n = time_s.size();
  if (first + 4 > n) return {};
  const double step = (time_s.back() - time_s[first]) / static_cast<double>(n - 1 - first);
  const auto min_lag = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(min_s / step)));
  const std::size_t max_lag = (n - first) / 2;
  std::vector<double> agree;  // by lag - min_lag
  for (std::size_t lag = min_lag; lag <= max_lag; ++lag) {
    std::size_t same = 0, total = 0;
    for (std::size_t k = first; k + lag < n; ++k) {
      for (std::size_t e = 0; e < contacts.touching[k].size(); ++e) {
        same += contacts.touching[k][e] == contacts.touching[k + lag][e] ? 1 : 0;
        ++total;
      }
    }
    agree.push_back(total > 0 ? static_cast<double>(same) / static_cast<double>(total) : 0.0);
  }
  if (agree.empty()) return {};
  const double best = *std::max_element(agree.begin(), agree.end());
  for (std::size_t i = 0; i < agree.size(); ++i) {
    // The first shift as good as the best, at its own local peak.
    if (agree[i] < best - slack) continue;
    while (i + 1 < agree.size() && agree[i + 1] > agree[i]) ++i;
    return {static_cast<double>(i + min_lag) * step, agree[i]};
  }
  return {};
}

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  const double pos = std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(values.size() - 1, lo + 1);
  return values[lo] + (pos - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

SlipSummary summarize_slip(const Contacts& contacts, std::size_t first_sample) {
  SlipSummary s;
  std::vector<double> all;
  const std::size_t nodes = contacts.spans.size();
  std::vector<double> sum(nodes, 0.0);
  std::vector<std::size_t> count(nodes, 0);
  for (std::size_t k = first_sample; k < contacts.slip_m_per_s.size(); ++k) {
    for (std::size_t n = 0; n < nodes; ++n) {
      const double v = contacts.slip_m_per_s[k][n];
      if (v < 0.0) continue;
      all.push_back(v);
      sum[n] += v;
      ++count[n];
    }
  }
  for (std::size_t n = 0; n < nodes; ++n) {
    s.mean_per_node_m_per_s.push_back(count[n] > 0 ? sum[n] / static_cast<double>(count[n]) : -1.0);
  }
  s.samples = all.size();
  if (!all.empty()) {
    double total = 0.0;
    for (const double v : all) total += v;
    s.mean_m_per_s = total / static_cast<double>(all.size());
    s.median_m_per_s = quantile(all, 0.5);
    s.p95_m_per_s = quantile(all, 0.95);
  }
  return s;
}

}  // namespace tensegrity::sim::analysis
