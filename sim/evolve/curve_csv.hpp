// SPDX-License-Identifier: Apache-2.0
#pragma once
// The learning curve as CSV, one row per generation:
// generation,episodes,best_score_m,mean_score_m,infeasible_rate,best_so_far_m,teams,infeasible
// Only numbers the run's config determines (no wall times), so that the curves of
// two runs, or of a run and its resumed twin, compare byte for byte.
#include <filesystem>
#include <string>
#include <vector>

#include "sim/evolve/coevolution.hpp"

namespace tensegrity::sim::evolve {

std::string curve_csv(const std::vector<GenerationStats>& curve);
// Atomic, the whole curve each time: a resumed run's file is the uninterrupted one's.
void write_curve_csv(const std::filesystem::path& path, const std::vector<GenerationStats>& curve);

}  // namespace tensegrity::sim::evolve
