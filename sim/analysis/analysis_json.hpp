// SPDX-License-Identifier: Apache-2.0
#pragma once
// The summary of `tensegrity analyze`: the numbers docs/reproduction.md sets beside the
// paper's Figures 10-12, as one JSON object.
#include <nlohmann/json.hpp>

#include "sim/analysis/analysis.hpp"

namespace tensegrity::sim::analysis {

nlohmann::json analysis_json(const EpisodeSeries& series, const Analysis& analysis, const AnalysisOptions& options);

}  // namespace tensegrity::sim::analysis
