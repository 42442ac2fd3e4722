// SPDX-License-Identifier: Apache-2.0
#include "cli/evolve_progress.hpp"

#include <cstdio>

namespace tensegrity::cli {

EvolveProgress::EvolveProgress(bool enabled, std::int64_t episode_budget)
    : enabled_(enabled), budget_(episode_budget), started_(std::chrono::steady_clock::now()) {}

void EvolveProgress::update(const sim::evolve::Coevolution& evolution, const sim::evolve::GenerationStats& stats) {
  if (!enabled_) return;
  // The rate counts this process's episodes only: a resumed run's earlier ones took
  // no time here.
  if (first_episodes_ < 0) first_episodes_ = stats.episodes - stats.teams;
  const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  const auto done_here = static_cast<double>(stats.episodes - first_episodes_);
  const double rate = elapsed_s > 0.0 ? done_here / elapsed_s : 0.0;
  const double eta_s = rate > 0.0 ? static_cast<double>(budget_ - stats.episodes) / rate : 0.0;
  const int eta_min = static_cast<int>(eta_s / 60.0);
  const int eta_sec = static_cast<int>(eta_s) % 60;
  std::fprintf(stderr,
               "\r\033[Kgen %d  episodes %lld/%lld  best %.2f m (so far %.2f)  mean %.2f m  infeasible %.0f%%  "
               "%.2f ep/s  ETA %dm%02ds",
               stats.generation, static_cast<long long>(stats.episodes), static_cast<long long>(budget_),
               stats.best_score_m, evolution.best().score_m, stats.mean_score_m, 100.0 * stats.infeasible_rate(), rate,
               eta_min, eta_sec);
  std::fflush(stderr);
  drawn_ = true;
}

void EvolveProgress::finish() {
  if (drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

}  // namespace tensegrity::cli
