// SPDX-License-Identifier: Apache-2.0
#pragma once
// A numeric CSV file (a header line of names, then rows of numbers), read strictly:
// every error names the file, the line and the column. Only the rows a caller keeps
// are stored, so a 100 MB telemetry file of which the view shows every 20th row
// costs a twentieth of it in memory.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace tensegrity::view {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CsvHeader {
  std::string source;  // the file, for messages
  std::vector<std::string> names;
  // Index of `name`, or -1.
  int find(const std::string& name) const;
};

struct CsvReadResult {
  std::size_t rows = 0;               // data rows read (all, kept or not)
  std::vector<std::string> warnings;  // e.g. a last line cut mid-write, dropped
};

// Reads `path`; calls `on_row(line_number, values)` for every data row, all values
// finite numbers. Throws InputError "FILE:LINE:COLUMN (NAME): ..." on a field that
// is not a number, a row with the wrong field count, or a file without rows. A last
// line without its newline that does not parse (a run killed mid-write) is dropped
// with a warning: the rows before it are good and are kept.
CsvReadResult read_numeric_csv(const std::filesystem::path& path, CsvHeader& header,
                               const std::function<void(std::size_t, std::span<const double>)>& on_row);

}  // namespace tensegrity::view
