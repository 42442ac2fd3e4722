// SPDX-License-Identifier: Apache-2.0
#include "sim/model/run_record.hpp"

#include <charconv>
#include <stdexcept>

#include "sim/model/model.hpp"

namespace tensegrity::sim {
namespace {

constexpr const char* kCableQuantities[] = {"rest_length_m", "length_m", "tension_n", "power_w"};
// Nine significant digits: a micrometre on a 1 km course, a millinewton on a 500 N cable.
constexpr int kDigits = 9;
// The longest a value formats to ("-1.23456789e-300" and its comma), with room to spare.
constexpr std::size_t kMaxValueChars = 32;

std::size_t value_count(const Model& model) {
  return 1 + 3 + 3 * static_cast<std::size_t>(model.robot().node_count()) +
         std::size(kCableQuantities) * static_cast<std::size_t>(model.cable_count()) + 3;
}

class RowBuilder {
 public:
  explicit RowBuilder(std::vector<char>& buffer) : begin_(buffer.data()), at_(begin_), end_(begin_ + buffer.size()) {}
  void add(double value) {
    if (at_ != begin_) *at_++ = ',';
    at_ = std::to_chars(at_, end_, value, std::chars_format::general, kDigits).ptr;
  }
  std::size_t finish() {
    *at_++ = '\n';
    return static_cast<std::size_t>(at_ - begin_);
  }

 private:
  char* begin_;
  char* at_;
  char* end_;
};

}  // namespace

std::string cable_column(int cable, std::string_view quantity) {
  return "cable" + std::to_string(cable) + "_" + std::string(quantity);
}

std::string legacy_cable_column(int cable, std::string_view quantity) {
  return std::string(quantity) + "_" + std::to_string(cable);
}

std::string run_record_header(const Model& model) {
  std::string h = "time_s,centre_x_m,centre_y_m,centre_z_m";
  for (int i = 0; i < model.robot().node_count(); ++i) {
    const std::string n = ",node" + std::to_string(i);
    h += n + "_x_m" + n + "_y_m" + n + "_z_m";
  }
  for (const char* what : kCableQuantities) {
    for (int m = 0; m < model.cable_count(); ++m) h += "," + cable_column(m, what);
  }
  return h + ",kinetic_energy_j,gravity_energy_j,elastic_energy_j";
}

RunRecordWriter::RunRecordWriter(const std::string& path, const Model& model)
    : path_(path), row_(value_count(model) * kMaxValueChars + 2) {
  file_ = std::fopen(path.c_str(), "w");
  if (file_ == nullptr) throw std::runtime_error(path + ": cannot create the run record");
  const std::string header = run_record_header(model) + "\n";
  std::fwrite(header.data(), 1, header.size(), file_);
}

RunRecordWriter::~RunRecordWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

void RunRecordWriter::write_row(double time_s, const Model& model) {
  RowBuilder row(row_);
  row.add(time_s);
  const auto centre = model.centre_m();
  for (int k = 0; k < 3; ++k) row.add(centre[k]);
  for (int i = 0; i < model.robot().node_count(); ++i) {
    const auto p = model.node_position(i);
    for (int k = 0; k < 3; ++k) row.add(p[k]);
  }
  for (const double v : model.rest_length_m()) row.add(v);
  for (const double v : model.length_m()) row.add(v);
  for (const double v : model.tension_n()) row.add(v);
  const auto tension = model.tension_n();
  const auto rate = model.rest_length_rate_m_per_s();
  for (std::size_t m = 0; m < tension.size(); ++m) row.add(tension[m] * rate[m]);
  row.add(model.kinetic_energy_j());
  row.add(model.gravity_energy_j());
  row.add(model.elastic_energy_j());
  std::fwrite(row_.data(), 1, row.finish(), file_);
}

void RunRecordWriter::close() {
  if (file_ == nullptr) return;
  const bool bad = std::ferror(file_) != 0;
  const bool close_failed = std::fclose(file_) != 0;
  file_ = nullptr;
  if (bad || close_failed) throw std::runtime_error(path_ + ": writing the run record failed");
}

}  // namespace tensegrity::sim
