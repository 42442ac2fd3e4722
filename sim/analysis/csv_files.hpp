// SPDX-License-Identifier: Apache-2.0
#pragma once
// The CSV files of `tensegrity analyze`, one per figure or table (names in
// docs/reproduction.md, "Figures 10-12"); tools/plot_analysis.py reads them.
#include <filesystem>
#include <string>
#include <vector>

#include "sim/analysis/analysis.hpp"

namespace tensegrity::sim::analysis {

// Writes every file into `dir` (created) and returns their names; throws naming the
// file that could not be written.
std::vector<std::string> write_csv_files(const std::filesystem::path& dir, const EpisodeSeries& series,
                                         const Analysis& analysis);

}  // namespace tensegrity::sim::analysis
