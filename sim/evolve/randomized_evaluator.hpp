// SPDX-License-Identifier: Apache-2.0
#pragma once
// Robust learning (`tensegrity evolve --randomize`): every team is scored on K models
// drawn from a randomization file (robot/randomization.hpp) and its K scores combined
// by a rule (the mean, or the lower quartile). The K models are drawn afresh every
// generation from (seed, generation) alone, so every team of a generation meets the
// same models, a run is the same in any thread count and after a resume, and no team
// is learned against one fixed set of models.
#include <memory>
#include <span>
#include <vector>

#include "robot/randomization.hpp"
#include "robot/robot.hpp"
#include "sim/evolve/config.hpp"
#include "sim/evolve/evaluator.hpp"

namespace tensegrity::sim::evolve {

class ThreadPool;

// The config's ranges, parsed; throws ConfigError when they do not fit the robot
// (rough ground drawn for a robot on the Bullet engine).
Randomization config_randomization(const EvolveConfig& config, const Robot& robot);

// A team's scores on its samples as the rule combines them: the mean in sample order,
// or the lower quartile (sorted, linear between the two nearest, as numpy's default).
double combine_sample_scores(SampleScore rule, std::vector<double> scores_m);

class RandomizedEvaluator final : public Evaluator {
 public:
  // Draws generation 1's models. threads <= 1: on the calling thread.
  RandomizedEvaluator(const Robot& robot, const EvolveConfig& config, int threads);
  ~RandomizedEvaluator() override;
  RandomizedEvaluator(const RandomizedEvaluator&) = delete;
  RandomizedEvaluator& operator=(const RandomizedEvaluator&) = delete;

  // A team infeasible on any of its models is infeasible: a gait that breaks one
  // plausible robot is not one to upload.
  std::vector<TeamResult> evaluate(std::span<const Team> teams) override;
  // Draws the generation's K models and drops the last ones' settled starts.
  void set_generation(int generation) override;

  int generation() const { return generation_; }
  const std::vector<Sample>& samples() const { return samples_; }
  const std::vector<Robot>& models() const { return models_; }

 private:
  Robot robot_;
  EvolveConfig config_;
  Randomization ranges_;
  int generation_ = 0;
  std::vector<Sample> samples_;
  std::vector<Robot> models_;
  std::unique_ptr<ThreadPool> pool_;
};

}  // namespace tensegrity::sim::evolve
