// SPDX-License-Identifier: Apache-2.0
#pragma once
// Everything that decides a coevolution run's result, so that a checkpoint can be
// checked against the run it is asked to continue. The thread count is not here on
// purpose: results do not depend on it.
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace tensegrity::sim::evolve {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Credit assignment: how a member's team scores become its fitness (paper, sec. 4).
enum class FitnessMethod {
  historical,  // mean of every score since the member was created (kept across generations)
  leniency,    // best score of this generation
  average,     // mean score of this generation (history cleared every generation)
};

const char* to_string(FitnessMethod method);
// Throws ConfigError naming the accepted values.
FitnessMethod parse_fitness_method(const std::string& text);

// How a copy of a survivor is mutated (docs/guide/evolve.md has both, with sources).
enum class Mutation {
  gaussian,  // every value of every copy moves by N(0, sigma^2), clamped
  // The author's NTRT operator (NeuroEvoMember::mutate): a copy stays as it is with
  // probability 1/2; otherwise each value moves with probability 1/2 by N(0, sigma^2),
  // clamped. NTRT's sigma is 0.03 of the normalised range.
  author,
};

const char* to_string(Mutation mutation);
Mutation parse_mutation(const std::string& text);
// NTRT's step as a share of the rest-length range (0.015 m on 0.6-1.1 m).
inline constexpr double kAuthorSigmaShareOfRange = 0.03;
// NTRT's probabilities: a copy is left unmutated, a value of a mutated copy is left.
inline constexpr double kAuthorCopyUntouchedProbability = 0.5;
inline constexpr double kAuthorValueUntouchedProbability = 0.5;

// A mutation step's schedule: sigma_m for anneal_start_episodes episodes, then
// geometrically to sigma_final_m over anneal_episodes more (mutation_sigma_m below).
struct StepSchedule {
  double sigma_m;
  double sigma_final_m;
  std::int64_t anneal_start_episodes;
  std::int64_t anneal_episodes;
};
// What `tensegrity evolve` breeds with under the Gaussian operator when no step option
// is given: the 0.05 m search step while gaits are being found, then down to 0.02 m by
// episode 5000, so that a population holding a gait keeps more of it in its copies
// (docs/reproduction.md, "The model choices, with their evidence", and docs/results/arms/compare-anneal40-5000.csv: generation mean at 5000 30.3 m against 21.8 m,
// mean best 32.2 m, 8 of 10 seeds at 37-39 m).
inline constexpr StepSchedule kDefaultGaussianSchedule{0.05, 0.02, 2000, 3000};

// How a team's scores on its sampled models (robust learning) become its score.
enum class SampleScore {
  mean,  // the mean over the samples
  q25,   // the lower quartile (linear between order statistics): what it rolls on a bad model
};

const char* to_string(SampleScore score);
SampleScore parse_sample_score(const std::string& text);
// At most this many sampled models per team: each costs a whole episode.
inline constexpr int kMaxRandomizeK = 64;

struct EvolveConfig {
  FitnessMethod method = FitnessMethod::historical;
  // 40 members, 20 replaced: the author's Config.ini has 10 and 5, which on this
  // model finds a rolling gait in 3 of 10 seeds by 5000 episodes; 40 and 20 find
  // one in 10 of 10 (docs/reproduction.md, "The model choices, with their evidence").
  int population = 40;  // members per cable population
  int teams = 50;       // random teams evaluated per generation
  int replace = 20;     // worst members replaced by mutated copies of the best
  // Mutation: every value of a copy gets a N(0, sigma^2) step, clamped to the limits.
  // sigma stays sigma_m for anneal_start_episodes episodes, then goes geometrically
  // to sigma_final_m over anneal_episodes more and stays there; anneal_episodes 0
  // keeps sigma_m. (The paper says only "mutate"; a step that explores a random
  // start is five times what refines a gait, docs/reproduction.md.)
  Mutation mutation = Mutation::gaussian;
  double sigma_m = 0.05;
  double sigma_final_m = 0.05;
  std::int64_t anneal_start_episodes = 0;
  std::int64_t anneal_episodes = 0;
  std::uint64_t seed = 0;
  std::int64_t episodes = 5000;  // budget; the last generation may have fewer teams
  int cables = 24;
  int complexity = 5;
  double min_rest_length_m = 0.6;
  double max_rest_length_m = 1.1;
  // What the teams are evaluated on; the algorithm itself does not read these.
  double period_s = 4.0;
  double duration_s = 60.0;
  // The time step teams are scored at, s; 0: the robot's own (its time_step_s).
  double dt_s = 0.0;
  // A team's episode ends once it provably cannot roll early_end_bar_m, its progress
  // bounded by early_end_speed_m_per_s; it then scores its distance so far scaled to
  // the whole episode, at most the bar (an approximation: docs/design/performance.md).
  // 0: every episode runs to its end.
  double early_end_bar_m = 0.0;
  double early_end_speed_m_per_s = 0.0;
  std::string robot_name;
  std::string robot_hash;
  // Robust learning: every team is scored on randomize_k models drawn afresh each
  // generation from these ranges (the canonical text of a randomization file,
  // robot/randomization.hpp), its scores combined by randomize_score. Empty: the
  // robot's own model alone.
  std::string randomization;
  int randomize_k = 1;
  SampleScore randomize_score = SampleScore::mean;
};

// The mutation step for copies bred after `episodes_done` episodes.
double mutation_sigma_m(const EvolveConfig& config, std::int64_t episodes_done);

// Throws ConfigError on the first nonsensical value (e.g. replace > population / 2).
void validate(const EvolveConfig& config);

nlohmann::json config_to_json(const EvolveConfig& config);
EvolveConfig config_from_json(const nlohmann::json& j);
// One line per field that differs, "field: a -> b"; empty when equal.
std::vector<std::string> config_differences(const EvolveConfig& a, const EvolveConfig& b);

}  // namespace tensegrity::sim::evolve
