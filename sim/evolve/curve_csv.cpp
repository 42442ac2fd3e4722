// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/curve_csv.hpp"

#include <cstdio>

#include "format/atomic_file.hpp"

namespace tensegrity::sim::evolve {

std::string curve_csv(const std::vector<GenerationStats>& curve) {
  std::string out = "generation,episodes,best_score_m,mean_score_m,infeasible_rate,best_so_far_m,teams,infeasible\n";
  char line[256];
  for (const auto& s : curve) {
    // %.17g: enough digits to be exact, so equal files mean equal runs.
    std::snprintf(line, sizeof line, "%d,%lld,%.17g,%.17g,%.17g,%.17g,%d,%d\n", s.generation,
                  static_cast<long long>(s.episodes), s.best_score_m, s.mean_score_m, s.infeasible_rate(),
                  s.best_so_far_m, s.teams, s.infeasible);
    out += line;
  }
  return out;
}

void write_curve_csv(const std::filesystem::path& path, const std::vector<GenerationStats>& curve) {
  format::write_file_atomic(path, curve_csv(curve));
}

}  // namespace tensegrity::sim::evolve
