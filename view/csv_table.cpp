// SPDX-License-Identifier: Apache-2.0
#include "view/csv_table.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string_view>

namespace tensegrity::view {

int CsvHeader::find(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return static_cast<int>(i);
  }
  return -1;
}

namespace {

std::string read_all(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open");
  std::ostringstream s;
  s << in.rdbuf();
  return std::move(s).str();
}

std::string_view trim_cr(std::string_view line) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  return line;
}

std::vector<std::string> split_names(std::string_view line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    out.emplace_back(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

// Empty when the row is good, else the reason (with line and column).
std::string parse_row(std::string_view line, const CsvHeader& header, std::size_t line_no, std::vector<double>& out) {
  out.clear();
  std::size_t start = 0;
  const std::string where = header.source + ":" + std::to_string(line_no) + ":";
  while (start <= line.size()) {
    const std::size_t comma = line.find(',', start);
    const std::size_t end = comma == std::string_view::npos ? line.size() : comma;
    const std::string_view field = line.substr(start, end - start);
    const std::size_t column = out.size() + 1;
    if (column > header.names.size()) {
      return where + " " + std::to_string(split_names(line).size()) + " fields, the header has " +
             std::to_string(header.names.size());
    }
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), v);
    if (ec != std::errc() || ptr != field.data() + field.size() || !std::isfinite(v)) {
      return where + std::to_string(column) + " (" + header.names[column - 1] + "): '" + std::string(field) +
             "' is not a finite number";
    }
    out.push_back(v);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  if (out.size() != header.names.size()) {
    return where + " " + std::to_string(out.size()) + " fields, the header has " + std::to_string(header.names.size());
  }
  return {};
}

}  // namespace

CsvReadResult read_numeric_csv(const std::filesystem::path& path, CsvHeader& header,
                               const std::function<void(std::size_t, std::span<const double>)>& on_row) {
  const std::string text = read_all(path);
  header.source = path.string();
  CsvReadResult result;
  std::size_t pos = 0;
  std::size_t line_no = 0;
  std::vector<double> values;
  while (pos < text.size()) {
    const std::size_t nl = text.find('\n', pos);
    const bool last_unterminated = nl == std::string::npos;
    const std::string_view line =
        trim_cr(std::string_view(text).substr(pos, last_unterminated ? std::string::npos : nl - pos));
    pos = last_unterminated ? text.size() : nl + 1;
    ++line_no;
    if (line_no == 1) {
      header.names = split_names(line);
      if (header.find("time_s") != 0) {
        throw InputError(header.source +
                         ":1:1: the first column must be time_s (a telemetry CSV of `tensegrity sim "
                         "--telemetry` or `tensegrity hil --record`)");
      }
      continue;
    }
    if (line.empty()) continue;
    const std::string error = parse_row(line, header, line_no, values);
    if (!error.empty()) {
      if (last_unterminated && result.rows > 0) {
        result.warnings.push_back(error + " (the last line, cut mid-write: dropped)");
        break;
      }
      throw InputError(error);
    }
    ++result.rows;
    on_row(line_no, values);
  }
  if (line_no == 0) throw InputError(header.source + ": empty file");
  if (result.rows == 0) throw InputError(header.source + ":2: no data rows after the header");
  return result;
}

}  // namespace tensegrity::view
