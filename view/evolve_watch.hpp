// SPDX-License-Identifier: Apache-2.0
#pragma once
// `tensegrity view --evolve DIR`: follows the checkpoint an evolution writes after
// every generation (DIR/checkpoint.json, `tensegrity evolve --checkpoint DIR`),
// running or finished, and turns it into the page's learning curve (best,
// generation mean, infeasible share per generation). When the best team so far
// changes it plays that team once in-process on the model, as the evolution scored
// it (settled start, the run's episode length), to make its replay.
#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace tensegrity::view {

struct EvolveWatchOptions {
  std::filesystem::path dir;
  std::filesystem::path robot;  // empty: robots/<the run's robot name>.json
  double poll_s = 1.0;
};

class EvolveWatch {
 public:
  explicit EvolveWatch(const EvolveWatchOptions& options);
  ~EvolveWatch();
  EvolveWatch(const EvolveWatch&) = delete;
  EvolveWatch& operator=(const EvolveWatch&) = delete;

  // {"dir","state":"waiting"|"running"|"finished"|"error","message","generation",
  //  "episodes","budget","best_score_m","best_generation","best_version",
  //  "replay_version","curve":{"generation":[...],"best_score_m":[...],
  //  "mean_score_m":[...],"infeasible_rate":[...],"best_so_far_m":[...]}}
  std::string curve_json() const;
  // The best team's replay; nullopt until the first one is simulated.
  std::optional<std::string> replay_json() const;
  // The run's robot; nullopt until the first checkpoint is read.
  std::optional<std::string> robot_json() const;

 private:
  void loop();
  bool poll();  // true when the checkpoint changed
  void simulate_best();

  EvolveWatchOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable stop_cv_;
  bool stopping_ = false;
  struct State;
  std::unique_ptr<State> state_;
  std::thread thread_;
};

}  // namespace tensegrity::view
