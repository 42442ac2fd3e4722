// SPDX-License-Identifier: Apache-2.0
// Checkpoints: a run stopped (or killed with SIGKILL) at any moment and resumed ends
// exactly as the uninterrupted run; damaged checkpoints and foreign configs are
// refused with a clear error.
#include "sim/evolve/checkpoint.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "sim/evolve/curve_csv.hpp"
#include "sim/evolve/driver.hpp"
#include "tests/sim/evolve/synthetic.hpp"

namespace tensegrity::sim::evolve {
namespace {

namespace fs = std::filesystem;

class Checkpoints : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    root_ = fs::temp_directory_path() / ("evolve_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  fs::path root_;
};

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

EvolveConfig config() { return testing::synthetic_config(FitnessMethod::historical, 600, 21); }

// The uninterrupted run's final state and curve.
struct Final {
  std::string state;
  std::string curve;
};

Final straight(const fs::path& dir) {
  FunctionEvaluator evaluator(testing::synthetic_score);
  DriverOptions options;
  options.checkpoint_dir = dir / "ckpt";
  options.curve_csv = dir / "curve.csv";
  auto result = drive(config(), evaluator, options);
  EXPECT_TRUE(result.evolution.done());
  return Final{checkpoint_to_json(config(), result.evolution.state()), read(dir / "curve.csv")};
}

Final resume(const fs::path& dir, std::vector<std::string>* warnings = nullptr) {
  FunctionEvaluator evaluator(testing::synthetic_score);
  DriverOptions options;
  options.checkpoint_dir = dir / "ckpt";
  options.curve_csv = dir / "curve.csv";
  options.resume = true;
  auto result = drive(config(), evaluator, options);
  EXPECT_TRUE(result.resumed);
  if (warnings) *warnings = result.warnings;
  return Final{checkpoint_to_json(config(), result.evolution.state()), read(dir / "curve.csv")};
}

void run_generations(const fs::path& dir, int generations) {
  FunctionEvaluator evaluator(testing::synthetic_score);
  DriverOptions options;
  options.checkpoint_dir = dir / "ckpt";
  options.curve_csv = dir / "curve.csv";
  options.max_generations = generations;
  (void)drive(config(), evaluator, options);
}

TEST_F(Checkpoints, StopAndResumeEqualsAnUninterruptedRun) {
  const Final expected = straight(root_ / "a");
  run_generations(root_ / "b", 4);
  const Checkpoint cp = parse_checkpoint(read(root_ / "b" / "ckpt" / kCheckpointFile), "b");
  EXPECT_EQ(cp.state.generation, 4);
  EXPECT_EQ(cp.state.episodes, 200);
  const Final got = resume(root_ / "b");
  EXPECT_EQ(got.state, expected.state);
  EXPECT_EQ(got.curve, expected.curve);
}

TEST_F(Checkpoints, ACrashInsideAGenerationLosesNothing) {
  const Final expected = straight(root_ / "a");
  // The evaluator dies in the middle of generation 7's batch.
  int calls = 0;
  FunctionEvaluator dying([&](const Team& team) {
    if (++calls == 6 * 50 + 17) throw std::runtime_error("crash");
    return testing::synthetic_score(team);
  });
  DriverOptions options;
  options.checkpoint_dir = root_ / "b" / "ckpt";
  options.curve_csv = root_ / "b" / "curve.csv";
  EXPECT_THROW((void)drive(config(), dying, options), std::runtime_error);
  const Final got = resume(root_ / "b");
  EXPECT_EQ(got.state, expected.state);
  EXPECT_EQ(got.curve, expected.curve);
}

TEST_F(Checkpoints, KilledWithSigkillAtARandomMomentAndResumed) {
  const Final expected = straight(root_ / "a");
  const fs::path dir = root_ / "b";
  fs::create_directories(dir);
  // A child process runs the same evolution slowly; the parent kills it mid-run.
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    FunctionEvaluator slow([](const Team& team) {
      std::this_thread::sleep_for(std::chrono::microseconds(500));
      return testing::synthetic_score(team);
    });
    DriverOptions options;
    options.checkpoint_dir = dir / "ckpt";
    options.curve_csv = dir / "curve.csv";
    try {
      (void)drive(config(), slow, options);
    } catch (...) {
      ::_exit(2);
    }
    ::_exit(0);
  }
  // Kill after the first checkpoint (so that there is something to resume), at a
  // moment that varies from run to run: inside a batch, during a save, or between.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!fs::exists(dir / "ckpt" / kCheckpointFile) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  const auto jitter_us = std::chrono::steady_clock::now().time_since_epoch().count() / 1000 % 60000;
  std::this_thread::sleep_for(std::chrono::microseconds(jitter_us));
  ::kill(child, SIGKILL);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the child finished before the kill; make it slower";
  const Final got = resume(dir);
  EXPECT_EQ(got.state, expected.state);
  EXPECT_EQ(got.curve, expected.curve);
}

TEST_F(Checkpoints, ACorruptCheckpointFallsBackToThePreviousOne) {
  const Final expected = straight(root_ / "a");
  run_generations(root_ / "b", 5);
  const fs::path current = root_ / "b" / "ckpt" / kCheckpointFile;
  const std::string text = read(current);
  {
    std::ofstream out(current, std::ios::trunc);
    out << text.substr(0, text.size() / 2);  // truncated, as by a damaged disk
  }
  std::vector<std::string> warnings;
  const Final got = resume(root_ / "b", &warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find(kCheckpointFile), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find(kPreviousCheckpointFile), std::string::npos) << warnings[0];
  EXPECT_EQ(got.state, expected.state);
  EXPECT_EQ(got.curve, expected.curve);
}

TEST_F(Checkpoints, NoUsableCheckpointIsAClearError) {
  run_generations(root_ / "b", 3);
  for (const char* name : {kCheckpointFile, kPreviousCheckpointFile}) {
    std::ofstream out(root_ / "b" / "ckpt" / name, std::ios::trunc);
    out << "{\"format\": \"tensegrity-evolve-checkpoint/1\", \"config\": ";
  }
  try {
    (void)load_checkpoint(root_ / "b" / "ckpt", config());
    FAIL() << "expected CheckpointError";
  } catch (const CheckpointError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no usable checkpoint"), std::string::npos) << what;
    EXPECT_NE(what.find(kCheckpointFile), std::string::npos) << what;
    EXPECT_NE(what.find(kPreviousCheckpointFile), std::string::npos) << what;
  }
}

TEST_F(Checkpoints, AnInconsistentCheckpointIsRejected) {
  run_generations(root_ / "b", 2);
  const std::string text = read(root_ / "b" / "ckpt" / kCheckpointFile);
  const auto tampered = [&](const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json j = nlohmann::json::parse(text);
    edit(j);
    return j.dump();
  };
  // Each is complete JSON but not a state the run could have been in.
  EXPECT_THROW((void)parse_checkpoint(tampered([](auto& j) { j["generation"] = 3; }), "x"), CheckpointError);
  EXPECT_THROW((void)parse_checkpoint(tampered([](auto& j) { j["populations"][0].erase(0); }), "x"), CheckpointError);
  EXPECT_THROW(
      (void)parse_checkpoint(tampered([](auto& j) { j["populations"][1][2]["rest_lengths_m"][0] = 2.0; }), "x"),
      CheckpointError);
  EXPECT_THROW((void)parse_checkpoint(tampered([](auto& j) { j["rng_state"] = "12 34"; }), "x"), CheckpointError);
  EXPECT_THROW((void)parse_checkpoint(tampered([](auto& j) { j.erase("curve"); }), "x"), CheckpointError);
  EXPECT_THROW((void)parse_checkpoint("not json", "x"), CheckpointError);
  EXPECT_NO_THROW((void)parse_checkpoint(text, "x"));
}

// An integer field holding a float, a number beyond its type or a string is refused
// naming the field; get<int>() would have cast a double of 4e57 to int (undefined
// behaviour, found by fuzz_evolve_checkpoint).
TEST_F(Checkpoints, AnIntegerFieldOutOfItsRangeOrNotAnIntegerIsNamed) {
  run_generations(root_ / "b", 2);
  const std::string text = read(root_ / "b" / "ckpt" / kCheckpointFile);
  const auto error_of = [&](const std::function<void(nlohmann::json&)>& edit) -> std::string {
    nlohmann::json j = nlohmann::json::parse(text);
    edit(j);
    try {
      (void)parse_checkpoint(j.dump(), "x");
    } catch (const CheckpointError& e) {
      return e.what();
    }
    return "accepted";
  };
  EXPECT_NE(error_of([](auto& j) { j["config"]["complexity"] = 4.4e57; }).find("complexity"), std::string::npos);
  EXPECT_NE(error_of([](auto& j) { j["config"]["cables"] = 4294967300LL; }).find("cables"), std::string::npos);
  EXPECT_NE(error_of([](auto& j) { j["config"]["seed"] = -1; }).find("seed"), std::string::npos);
  EXPECT_NE(error_of([](auto& j) { j["config"]["anneal_episodes"] = 1.5; }).find("anneal_episodes"), std::string::npos);
  EXPECT_NE(error_of([](auto& j) { j["generation"] = "2"; }).find("generation"), std::string::npos);
  EXPECT_NE(error_of([](auto& j) { j["curve"][0]["teams"] = 1e300; }).find("teams"), std::string::npos);
}

// Checkpoints written before the mutation step could anneal have no schedule: they
// mutated with sigma_m throughout, and they resume that way.
TEST_F(Checkpoints, OneWithoutAMutationScheduleResumesWithAConstantStep) {
  run_generations(root_ / "b", 2);
  nlohmann::json j = nlohmann::json::parse(read(root_ / "b" / "ckpt" / kCheckpointFile));
  ASSERT_TRUE(j["config"].contains("anneal_episodes"));
  j["config"].erase("sigma_final_m");
  j["config"].erase("anneal_episodes");
  const EvolveConfig old = parse_checkpoint(j.dump(), "x").config;
  EXPECT_EQ(old.anneal_episodes, 0);
  EXPECT_DOUBLE_EQ(old.sigma_final_m, old.sigma_m);
  EXPECT_DOUBLE_EQ(mutation_sigma_m(old, 100000), config().sigma_m);
}

TEST_F(Checkpoints, ResumingWithAnotherConfigIsRefused) {
  run_generations(root_ / "b", 2);
  EvolveConfig other = config();
  other.sigma_m = 0.03;  // the synthetic config's is 0.01
  other.seed = 22;
  FunctionEvaluator evaluator(testing::synthetic_score);
  DriverOptions options;
  options.checkpoint_dir = root_ / "b" / "ckpt";
  options.resume = true;
  try {
    (void)drive(other, evaluator, options);
    FAIL() << "expected CheckpointError";
  } catch (const CheckpointError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("another config"), std::string::npos) << what;
    EXPECT_NE(what.find("sigma_m: 0.01 -> 0.03"), std::string::npos) << what;
    EXPECT_NE(what.find("seed: 21 -> 22"), std::string::npos) << what;
  }
}

TEST_F(Checkpoints, ALargerBudgetContinuesAFinishedRunAsIfItHadBeenOneRun) {
  const Final expected = straight(root_ / "a");  // 600 episodes
  FunctionEvaluator evaluator(testing::synthetic_score);
  DriverOptions options;
  options.checkpoint_dir = root_ / "b" / "ckpt";
  options.curve_csv = root_ / "b" / "curve.csv";
  EvolveConfig short_run = config();
  short_run.episodes = 300;
  EXPECT_TRUE(drive(short_run, evaluator, options).evolution.done());
  const Final got = resume(root_ / "b");
  EXPECT_EQ(got.state, expected.state);
  EXPECT_EQ(got.curve, expected.curve);
}

TEST_F(Checkpoints, ALargerBudgetIsRefusedWhenTheOldOneCutAGenerationShort) {
  FunctionEvaluator evaluator(testing::synthetic_score);
  DriverOptions options;
  options.checkpoint_dir = root_ / "b" / "ckpt";
  EvolveConfig short_run = config();
  short_run.episodes = 320;  // 6 generations of 50, then one of 20
  (void)drive(short_run, evaluator, options);
  options.resume = true;
  try {
    (void)drive(config(), evaluator, options);
    FAIL() << "expected CheckpointError";
  } catch (const CheckpointError& e) {
    EXPECT_NE(std::string(e.what()).find("episodes: 320 -> 600"), std::string::npos) << e.what();
  }
}

TEST_F(Checkpoints, ASmallerBudgetIsRefused) {
  run_generations(root_ / "b", 2);
  EvolveConfig other = config();
  other.episodes = 500;
  FunctionEvaluator evaluator(testing::synthetic_score);
  DriverOptions options;
  options.checkpoint_dir = root_ / "b" / "ckpt";
  options.resume = true;
  EXPECT_THROW((void)drive(other, evaluator, options), CheckpointError);
}

TEST_F(Checkpoints, AnExistingCheckpointIsNotOverwrittenWithoutResume) {
  run_generations(root_ / "b", 1);
  FunctionEvaluator evaluator(testing::synthetic_score);
  DriverOptions options;
  options.checkpoint_dir = root_ / "b" / "ckpt";
  EXPECT_THROW((void)drive(config(), evaluator, options), CheckpointError);
}

TEST_F(Checkpoints, ResumeWithoutACheckpointStartsFresh) {
  FunctionEvaluator evaluator(testing::synthetic_score);
  DriverOptions options;
  options.checkpoint_dir = root_ / "none";
  options.resume = true;
  options.max_generations = 1;
  const auto result = drive(config(), evaluator, options);
  EXPECT_FALSE(result.resumed);
  EXPECT_EQ(result.evolution.generation(), 1);
}

}  // namespace
}  // namespace tensegrity::sim::evolve
