// SPDX-License-Identifier: Apache-2.0
#pragma once
// An evolution as a user asks for one (`tensegrity evolve`), behind two calls: the
// options as given become a checked configuration (request_config), and
// run_evolution evolves to the budget (checkpointed, resumable), scores the best
// team once more, plays its gait at the robot's own step and writes the policy.
// The command line only parses and prints.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "robot/policy.hpp"
#include "robot/robot.hpp"
#include "sim/evolve/config.hpp"
#include "sim/evolve/driver.hpp"
#include "sim/evolve/evaluator.hpp"
#include "sim/model/episode.hpp"

namespace tensegrity::sim::evolve {

// The options of an evolution as a user gives them; a negative value is one not
// given. With none of the four step options given the Gaussian operator breeds with
// kDefaultGaussianSchedule; with any given, the user sets the schedule: the step
// defaults to the operator's own, the final step to the step, the rest to 0.
struct EvolveRequest {
  std::string method = "historical";
  std::string mutation = "gaussian";
  int population = EvolveConfig{}.population;
  int teams = EvolveConfig{}.teams;
  int replace = EvolveConfig{}.replace;
  double sigma_m = -1.0;
  double sigma_final_m = -1.0;
  std::int64_t anneal_episodes = -1;
  std::int64_t anneal_start_episodes = -1;
  std::uint64_t seed = 1;
  std::int64_t episodes = 5000;
  int complexity = 5;
  double period_s = 4.0;
  double duration_s = 60.0;
  double dt_s = 0.0;          // 0: the robot's learning step
  double early_end_m = -1.0;  // negative: the robot's learning.early_end
  // Robust learning: a randomization file (robot/randomization.hpp); empty: none.
  std::string randomize;
  int randomize_k = 8;
  std::string randomize_score = "mean";
};

// Throws ConfigError naming the option or the value that does not work.
EvolveConfig request_config(const EvolveRequest& request, const Robot& robot);

struct RunFiles {
  std::filesystem::path policy;          // the best team's policy file
  std::filesystem::path curve_csv;       // the learning curve
  std::filesystem::path checkpoint_dir;  // empty: no checkpoints
  bool resume = false;                   // continue the run checkpointed there
};

struct EvolveOutcome {
  DriverResult result;
  // The best team evaluated once more, alone (randomized: on the next generation's
  // models, which it has not met).
  TeamResult final_result;
  EpisodeResult gait;  // its episode at the robot's own step
  Policy policy;       // as written to RunFiles::policy
  double wall_s = 0.0;
};

// Throws CheckpointError when the checkpoint cannot be resumed or written.
EvolveOutcome run_evolution(const Robot& robot, const EvolveConfig& config, Evaluator& evaluator, const RunFiles& files,
                            const std::function<void(const Coevolution&, const GenerationStats&)>& on_generation);

}  // namespace tensegrity::sim::evolve
