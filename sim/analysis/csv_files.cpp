// SPDX-License-Identifier: Apache-2.0
#include "sim/analysis/csv_files.hpp"

#include <fstream>
#include <functional>
#include <stdexcept>

namespace tensegrity::sim::analysis {
namespace {

using Writer = std::function<void(std::ostream&)>;

void write_file(const std::filesystem::path& dir, const std::string& name, const Writer& body,
                std::vector<std::string>& written) {
  const auto path = dir / name;
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path.string() + ": cannot open for writing");
  out.precision(8);
  body(out);
  out.flush();
  if (!out) throw std::runtime_error(path.string() + ": writing failed");
  written.push_back(name);
}

void header_per(std::ostream& out, const char* first, const char* prefix, std::size_t n, const char* suffix) {
  out << first;
  for (std::size_t i = 0; i < n; ++i) out << ',' << prefix << i << suffix;
  out << '\n';
}

void matrix(std::ostream& out, const Matrix& m) {
  header_per(out, "cable", "cable", m.size(), "");
  for (std::size_t i = 0; i < m.size(); ++i) {
    out << i;
    for (const double v : m[i]) out << ',' << v;
    out << '\n';
  }
}

void lags(std::ostream& out, const std::vector<std::vector<int>>& lag) {
  header_per(out, "cable", "cable", lag.size(), "");
  for (std::size_t i = 0; i < lag.size(); ++i) {
    out << i;
    for (const int v : lag[i]) out << ',' << v;
    out << '\n';
  }
}

void linkage(std::ostream& out, const Dendrogram& tree) {
  out << "a,b,height,size\n";
  for (const auto& m : tree.merges) out << m.a << ',' << m.b << ',' << m.height << ',' << m.size << '\n';
}

void muscles(std::ostream& out, const Analysis& a) {
  out << "cable,rest_min_m,rest_max_m,rest_mean_m,length_mean_m,tension_mean_n,tension_max_n,power_mean_w\n";
  for (const auto& m : a.muscles) {
    out << m.cable << ',' << m.rest_min_m << ',' << m.rest_max_m << ',' << m.rest_mean_m << ',' << m.length_mean_m
        << ',' << m.tension_mean_n << ',' << m.tension_max_n << ',' << m.power_mean_w << '\n';
  }
}

void timeseries(std::ostream& out, const EpisodeSeries& s, const Analysis& a) {
  out << "time_s,rest_mean_m,length_mean_m,tension_mean_n,tension_max_n,kinetic_j,elastic_j,gravity_j,power_mean_w";
  for (int m = 0; m < s.cables(); ++m) out << ",cable" << m << "_power_w";
  out << '\n';
  for (std::size_t k = 0; k < a.robot.size(); ++k) {
    const auto& r = a.robot[k];
    out << r.time_s << ',' << r.rest_mean_m << ',' << r.length_mean_m << ',' << r.tension_mean_n << ','
        << r.tension_max_n << ',' << r.kinetic_j << ',' << r.elastic_j << ',' << r.gravity_j << ',' << r.power_mean_w;
    for (const double p : s.motor_power_w[k]) out << ',' << p;
    out << '\n';
  }
}

void signals(std::ostream& out, const EpisodeSeries& s) {
  header_per(out, "time_s", "cable", static_cast<std::size_t>(s.cables()), "_rest_m");
  for (std::size_t k = 0; k < s.samples(); ++k) {
    out << s.time_s[k];
    for (const double v : s.rest_length_m[k]) out << ',' << v;
    out << '\n';
  }
}

void clusters(std::ostream& out, const Analysis& a) {
  out << "cable,cluster,aligned_cluster,leaf_position,aligned_leaf_position\n";
  std::vector<int> pos(a.clusters.size()), aligned_pos(a.clusters.size());
  for (std::size_t i = 0; i < a.tree.leaf_order.size(); ++i) {
    pos[static_cast<std::size_t>(a.tree.leaf_order[i])] = static_cast<int>(i);
    aligned_pos[static_cast<std::size_t>(a.aligned_tree.leaf_order[i])] = static_cast<int>(i);
  }
  for (std::size_t c = 0; c < a.clusters.size(); ++c) {
    out << c << ',' << a.clusters[c] << ',' << a.aligned_clusters[c] << ',' << pos[c] << ',' << aligned_pos[c] << '\n';
  }
}

void contacts(std::ostream& out, const EpisodeSeries& s, const Analysis& a) {
  const auto nodes = static_cast<std::size_t>(s.nodes());
  out << "time_s";
  for (std::size_t n = 0; n < nodes; ++n) out << ",endcap" << n << "_touching";
  for (std::size_t n = 0; n < nodes; ++n) out << ",endcap" << n << "_slip_m_per_s";
  out << '\n';
  for (std::size_t k = 0; k < s.samples(); ++k) {
    out << s.time_s[k];
    for (std::size_t n = 0; n < nodes; ++n) out << ',' << (a.contacts.touching[k][n] ? 1 : 0);
    for (std::size_t n = 0; n < nodes; ++n) {
      out << ',';
      if (a.contacts.slip_m_per_s[k][n] >= 0.0) out << a.contacts.slip_m_per_s[k][n];
    }
    out << '\n';
  }
}

void faces(std::ostream& out, const Analysis& a) {
  out << "index,start_s,end_s,endcap_a,endcap_b,endcap_c,closed\n";
  for (std::size_t i = 0; i < a.faces.size(); ++i) {
    const auto& f = a.faces[i];
    out << i << ',' << f.start_s << ',' << f.end_s << ',' << f.nodes[0] << ',' << f.nodes[1] << ',' << f.nodes[2] << ','
        << (f.closed ? 1 : 0) << '\n';
  }
}

void endcaps(std::ostream& out, const Analysis& a) {
  out << "endcap,touched,share_touching,touchdowns,slip_mean_m_per_s\n";
  for (std::size_t n = 0; n < a.contacts.spans.size(); ++n) {
    out << n << ',' << (a.contacts.spans[n].empty() ? 0 : 1) << ',' << a.contacts.share[n] << ','
        << a.contacts.spans[n].size() << ',';
    if (a.slip.mean_per_node_m_per_s[n] >= 0.0) out << a.slip.mean_per_node_m_per_s[n];
    out << '\n';
  }
}

}  // namespace

std::vector<std::string> write_csv_files(const std::filesystem::path& dir, const EpisodeSeries& s, const Analysis& a) {
  std::filesystem::create_directories(dir);
  std::vector<std::string> w;
  write_file(
      dir, "fig10_11_muscles.csv", [&](std::ostream& o) { muscles(o, a); }, w);
  write_file(
      dir, "fig11_timeseries.csv", [&](std::ostream& o) { timeseries(o, s, a); }, w);
  write_file(
      dir, "fig12_signals.csv", [&](std::ostream& o) { signals(o, s); }, w);
  write_file(
      dir, "fig12_correlation.csv", [&](std::ostream& o) { matrix(o, a.correlation); }, w);
  write_file(
      dir, "fig12_linkage.csv", [&](std::ostream& o) { linkage(o, a.tree); }, w);
  write_file(
      dir, "fig12_aligned_correlation.csv", [&](std::ostream& o) { matrix(o, a.aligned.r); }, w);
  write_file(
      dir, "fig12_aligned_lag_samples.csv", [&](std::ostream& o) { lags(o, a.aligned.lag); }, w);
  write_file(
      dir, "fig12_aligned_linkage.csv", [&](std::ostream& o) { linkage(o, a.aligned_tree); }, w);
  write_file(
      dir, "fig12_clusters.csv", [&](std::ostream& o) { clusters(o, a); }, w);
  write_file(
      dir, "contacts.csv", [&](std::ostream& o) { contacts(o, s, a); }, w);
  write_file(
      dir, "faces.csv", [&](std::ostream& o) { faces(o, a); }, w);
  write_file(
      dir, "endcaps.csv", [&](std::ostream& o) { endcaps(o, a); }, w);
  return w;
}

}  // namespace tensegrity::sim::analysis
