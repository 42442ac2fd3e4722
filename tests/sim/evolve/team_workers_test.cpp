// SPDX-License-Identifier: Apache-2.0
// The threads behind the MPI evaluator and the serving ranks: every submitted team
// comes back once under its job id, errors come back as text, the owner is never
// blocked longer than it asked, and destruction with teams still queued ends.
#include "sim/evolve/team_workers.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <map>
#include <stdexcept>
#include <thread>

namespace tensegrity::sim::evolve {
namespace {

using namespace std::chrono_literals;

Team team_of(double v) { return Team{{{v}}}; }

std::map<std::uint64_t, TeamWorkers::Finished> collect_all(TeamWorkers& workers, std::size_t count) {
  std::map<std::uint64_t, TeamWorkers::Finished> out;
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (out.size() < count && std::chrono::steady_clock::now() < deadline) {
    for (auto& f : workers.collect(10ms)) {
      EXPECT_TRUE(out.emplace(f.job, f).second) << "job " << f.job << " came back twice";
    }
  }
  return out;
}

TEST(TeamWorkers, EveryJobComesBackOnceWithItsResult) {
  for (int threads : {1, 3}) {
    TeamWorkers workers([](const Team& t) { return TeamResult{2.0 * t.rest_lengths_m[0][0], true}; }, threads);
    EXPECT_EQ(workers.threads(), threads);
    for (std::uint64_t j = 0; j < 50; ++j) workers.submit(100 + j, team_of(static_cast<double>(j)));
    const auto done = collect_all(workers, 50);
    ASSERT_EQ(done.size(), 50u);
    for (std::uint64_t j = 0; j < 50; ++j) {
      EXPECT_EQ(done.at(100 + j).result.score_m, 2.0 * static_cast<double>(j));
      EXPECT_TRUE(done.at(100 + j).error.empty());
    }
    EXPECT_EQ(workers.in_flight(), 0u);
  }
}

TEST(TeamWorkers, ErrorsComeBackAsText) {
  TeamWorkers workers(
      [](const Team& t) -> TeamResult {
        if (t.rest_lengths_m[0][0] > 0.5) throw std::runtime_error("diverged");
        return TeamResult{1.0, true};
      },
      2);
  workers.submit(1, team_of(0.1));
  workers.submit(2, team_of(0.9));
  const auto done = collect_all(workers, 2);
  EXPECT_TRUE(done.at(1).error.empty());
  EXPECT_EQ(done.at(2).error, "diverged");
}

TEST(TeamWorkers, InFlightCountsUntilCollectedAndCollectWaitsOnlyAsAsked) {
  std::atomic<bool> release{false};
  TeamWorkers workers(
      [&](const Team&) {
        while (!release) std::this_thread::sleep_for(1ms);
        return TeamResult{};
      },
      1);
  workers.submit(1, team_of(0));
  workers.submit(2, team_of(0));
  EXPECT_EQ(workers.in_flight(), 2u);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_TRUE(workers.collect(20ms).empty());
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 5s);
  release = true;
  EXPECT_EQ(collect_all(workers, 2).size(), 2u);
  EXPECT_EQ(workers.in_flight(), 0u);
}

TEST(TeamWorkers, DestroyedWithTeamsQueued) {
  std::atomic<int> ran{0};
  {
    TeamWorkers workers(
        [&](const Team&) {
          ++ran;
          std::this_thread::sleep_for(20ms);
          return TeamResult{};
        },
        1);
    for (std::uint64_t j = 0; j < 100; ++j) workers.submit(j, team_of(0));
    std::this_thread::sleep_for(5ms);
  }
  EXPECT_LT(ran.load(), 100);
}

}  // namespace
}  // namespace tensegrity::sim::evolve
