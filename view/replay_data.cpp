// SPDX-License-Identifier: Apache-2.0
#include "view/replay_data.hpp"

#include <cmath>
#include <cstdio>
#include <memory>

#include "sim/model/telemetry.hpp"
#include "view/csv_table.hpp"
#include "view/json_numbers.hpp"

namespace tensegrity::view {

ReplayBuilder::ReplayBuilder(int nodes, int cables, bool has_energy, double interval_s) : interval_s_(interval_s) {
  frames_.nodes = nodes;
  frames_.cables = cables;
  frames_.has_energy = has_energy;
}

void ReplayBuilder::add(double time_s, std::span<const double> node_m, std::span<const double> rest_length_m,
                        std::span<const double> tension_n, std::span<const double> energy_j) {
  frames_.time_s.push_back(time_s);
  for (double v : node_m) frames_.node_m.push_back(static_cast<float>(v));
  for (double v : rest_length_m) frames_.rest_length_m.push_back(static_cast<float>(v));
  for (double v : tension_n) frames_.tension_n.push_back(static_cast<float>(v));
  if (frames_.has_energy) {
    for (double v : energy_j) frames_.energy_j.push_back(static_cast<float>(v));
  }
  next_s_ = time_s + interval_s_ - 1e-9;
}

namespace {

template <typename T>
std::vector<T> every_nth(const std::vector<T>& v, std::size_t width, std::size_t step) {
  std::vector<T> out;
  for (std::size_t f = 0; f * width < v.size(); f += step) {
    out.insert(out.end(), v.begin() + static_cast<std::ptrdiff_t>(f * width),
               v.begin() + static_cast<std::ptrdiff_t>((f + 1) * width));
  }
  return out;
}

}  // namespace

ReplayFrames ReplayBuilder::take() {
  ReplayFrames f = std::move(frames_);
  if (f.frames() > kMaxFrames) {
    const std::size_t step = (f.frames() + kMaxFrames - 1) / kMaxFrames;
    f.time_s = every_nth(f.time_s, 1, step);
    f.node_m = every_nth(f.node_m, static_cast<std::size_t>(f.nodes) * 3, step);
    f.rest_length_m = every_nth(f.rest_length_m, static_cast<std::size_t>(f.cables), step);
    f.tension_n = every_nth(f.tension_n, static_cast<std::size_t>(f.cables), step);
    if (f.has_energy) f.energy_j = every_nth(f.energy_j, 3, step);
  }
  return f;
}

namespace {

// Column indices of one quantity, one per cable; throws naming the first missing
// column and both accepted spellings (a HIL record of an older version has the second).
std::vector<int> cable_columns(const CsvHeader& h, int cables, const char* what) {
  std::vector<int> out;
  for (int m = 0; m < cables; ++m) {
    const std::string name = sim::cable_column(m, what);
    const std::string legacy = sim::legacy_cable_column(m, what);
    int i = h.find(name);
    if (i < 0) i = h.find(legacy);
    if (i < 0) throw InputError(h.source + ":1: no column " + name + " (or " + legacy + ")");
    out.push_back(i);
  }
  return out;
}

std::vector<int> node_columns(const CsvHeader& h, int nodes) {
  std::vector<int> out;
  for (int n = 0; n < nodes; ++n) {
    for (const char* axis : {"x", "y", "z"}) {
      const std::string name = "node" + std::to_string(n) + "_" + axis + "_m";
      const int i = h.find(name);
      if (i < 0) {
        throw InputError(h.source + ":1: no column " + name +
                         ": the view needs every end cap's position (a record of `tensegrity sim --telemetry`, or of "
                         "`tensegrity hil --record` from this version on)");
      }
      out.push_back(i);
    }
  }
  return out;
}

}  // namespace

ReplayFrames load_replay_csv(const std::filesystem::path& path, const sim::Robot& robot,
                             std::vector<std::string>& warnings) {
  CsvHeader header;
  std::vector<int> nodes, rest, tension, energy;
  std::unique_ptr<ReplayBuilder> builder;
  std::vector<double> n_buf, r_buf, t_buf, e_buf;
  double last_time = -INFINITY;
  const CsvReadResult read = read_numeric_csv(path, header, [&](std::size_t line, std::span<const double> row) {
    if (!builder) {  // the header is known from the first row on
      nodes = node_columns(header, robot.node_count());
      rest = cable_columns(header, robot.cable_count(), "rest_length_m");
      tension = cable_columns(header, robot.cable_count(), "tension_n");
      for (const char* e : {"kinetic_energy_j", "gravity_energy_j", "elastic_energy_j"}) {
        if (header.find(e) >= 0) energy.push_back(header.find(e));
      }
      if (energy.size() != 3) energy.clear();
      builder = std::make_unique<ReplayBuilder>(robot.node_count(), robot.cable_count(), !energy.empty());
    }
    const double t = row[0];
    if (t < last_time) {
      throw InputError(header.source + ":" + std::to_string(line) + ":1 (time_s): time goes back (" +
                       std::to_string(t) + " s after " + std::to_string(last_time) + " s)");
    }
    last_time = t;
    if (!builder->wants(t)) return;
    auto pick = [&row](const std::vector<int>& cols, std::vector<double>& buf) {
      buf.clear();
      for (int c : cols) buf.push_back(row[static_cast<std::size_t>(c)]);
      return std::span<const double>(buf);
    };
    builder->add(t, pick(nodes, n_buf), pick(rest, r_buf), pick(tension, t_buf), pick(energy, e_buf));
  });
  warnings.insert(warnings.end(), read.warnings.begin(), read.warnings.end());
  return builder->take();
}

std::string replay_json(const ReplayFrames& f, const std::string& source) {
  std::vector<float> centre;
  std::vector<float> distance;
  const std::size_t n = static_cast<std::size_t>(f.nodes);
  double x0 = 0.0, y0 = 0.0;
  for (std::size_t k = 0; k < f.frames(); ++k) {
    double c[3] = {0.0, 0.0, 0.0};
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t a = 0; a < 3; ++a) c[a] += f.node_m[(k * n + i) * 3 + a];
    }
    for (double& v : c) v /= static_cast<double>(n);
    if (k == 0) x0 = c[0], y0 = c[1];
    for (double v : c) centre.push_back(static_cast<float>(v));
    distance.push_back(static_cast<float>(std::hypot(c[0] - x0, c[1] - y0)));
  }
  std::string out = "{\"source\":" + json_string(source) + ",\"frames\":" + std::to_string(f.frames());
  out += ",\"nodes\":" + std::to_string(f.nodes) + ",\"cables\":" + std::to_string(f.cables);
  append_array(out, "time_s", f.time_s, "%.4f");
  append_array(out, "node_m", f.node_m, "%.4f");
  append_array(out, "rest_length_m", f.rest_length_m, "%.4f");
  append_array(out, "tension_n", f.tension_n, "%.1f");
  if (f.has_energy) {
    append_array(out, "energy_j", f.energy_j, "%.2f");
  } else {
    out += ",\"energy_j\":null";
  }
  append_array(out, "centre_m", centre, "%.4f");
  append_array(out, "distance_m", distance, "%.4f");
  out += "}";
  return out;
}

}  // namespace tensegrity::view
