// SPDX-License-Identifier: Apache-2.0
#pragma once
// The summary of `tensegrity analyze`: the numbers docs/reproduction.md sets beside the
// paper's Figures 10-12, as one JSON object.
#include <nlohmann/json.hpp>

#include "sim/analysis/analysis.hpp"
#include "sim/model/episode.hpp"

namespace tensegrity::cli {

nlohmann::json analysis_json(const sim::analysis::EpisodeSeries& series, const sim::analysis::Analysis& analysis,
                             const sim::analysis::AnalysisOptions& options);

// The readable form of the same summary.
void print_analysis_summary(const nlohmann::json& summary);

}  // namespace tensegrity::cli
