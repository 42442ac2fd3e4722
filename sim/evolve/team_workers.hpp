// SPDX-License-Identifier: Apache-2.0
#pragma once
// Persistent threads that evaluate teams handed to them one at a time and keep the
// results until their owner collects them. Unlike ThreadPool (one batch, caller
// blocked until it is done), the owner stays free in between: the MPI dispatcher on
// rank 0 and the serving loop of the other ranks feed these threads while they talk
// to the other ranks, one team per idle thread.
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "sim/evolve/evaluator.hpp"

namespace tensegrity::sim::evolve {

class TeamWorkers {
 public:
  struct Finished {
    std::uint64_t job = 0;
    TeamResult result;
    std::string error;  // what the function threw; empty when it returned
  };

  // threads >= 1 (unlike ThreadPool, never the calling thread: it must stay free).
  TeamWorkers(TeamFunction function, int threads);
  // Waits for the teams being evaluated; queued ones are dropped.
  ~TeamWorkers();
  TeamWorkers(const TeamWorkers&) = delete;
  TeamWorkers& operator=(const TeamWorkers&) = delete;

  int threads() const { return static_cast<int>(threads_.size()); }
  void submit(std::uint64_t job, Team team);
  // Teams submitted and not collected yet (queued, running or finished).
  std::size_t in_flight() const;
  // The finished teams, in the order they finished; when none has, waits up to
  // `wait` for one.
  std::vector<Finished> collect(std::chrono::microseconds wait);

 private:
  struct Job {
    std::uint64_t id = 0;
    Team team;
  };
  void work();

  TeamFunction function_;
  mutable std::mutex mutex_;
  std::condition_variable queued_;
  std::condition_variable finished_;
  std::deque<Job> queue_;
  std::vector<Finished> done_;
  std::size_t in_flight_ = 0;
  bool stop_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace tensegrity::sim::evolve
