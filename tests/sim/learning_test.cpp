// SPDX-License-Identifier: Apache-2.0
// How a robot is learned: its learning step and its early end (robot description's
// `learning`), the episode rule that ends a team once it cannot reach the bar, and
// what such a team scores.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "sim/model/core_controller.hpp"
#include "sim/model/episode.hpp"
#include "sim/evolve/episode_evaluator.hpp"
#include "robot/policy.hpp"
#include "robot/robot.hpp"
#include "tests/robot/robot_json.hpp"

namespace tensegrity::sim {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

json robot_json(const std::string& name) { return test_files::shipped_robot_json(name); }

std::string error_of(const json& doc) { return test_files::robot_error_of(doc); }

TEST(Learning, AbsentTheRobotLearnsAtItsOwnStepAndRunsEveryEpisodeToItsEnd) {
  json doc = robot_json("superball");
  doc.erase("learning");
  const Robot robot = parse_robot(doc.dump());
  EXPECT_EQ(robot.learning_time_step_s, robot.time_step_s);
  EXPECT_EQ(robot.early_end_bar_m, 0.0);
  EXPECT_EQ(evolve::default_learning_dt_s(robot), 0.0);
}

TEST(Learning, TheDefaultRobotLearnsAt2MsAndTheSpinHeldOneAtItsOwnStep) {
  const Robot paper = load_robot(default_robot_path());
  EXPECT_EQ(paper.time_step_s, 0.001);
  EXPECT_EQ(paper.learning_time_step_s, 0.002);
  EXPECT_EQ(evolve::default_learning_dt_s(paper), 0.002);
  EXPECT_GT(paper.early_end_bar_m, 0.0);
  EXPECT_GT(paper.early_end_max_speed_m_per_s, 0.0);
  const Robot spin_held = load_robot(robot_path_named("superball-spin-held"));
  EXPECT_EQ(evolve::default_learning_dt_s(spin_held), 0.0);
  EXPECT_EQ(spin_held.early_end_bar_m, 0.0);
}

TEST(Learning, BadFieldsAreNamed) {
  json doc = robot_json("superball");
  doc["learning"] = {{"time_step_s", 0.02}};
  EXPECT_THAT(error_of(doc), HasSubstr("learning.time_step_s"));
  doc["learning"] = {{"time_step_s", -0.002}};
  EXPECT_THAT(error_of(doc), HasSubstr("learning.time_step_s"));
  doc["learning"] = {{"timestep_s", 0.002}};
  EXPECT_THAT(error_of(doc), HasSubstr("learning.timestep_s: unknown field"));
  doc["learning"] = {{"early_end", {{"bar_m", 20.0}}}};
  EXPECT_THAT(error_of(doc), HasSubstr("learning.early_end.max_speed_m_per_s"));
  doc["learning"] = {{"early_end", {{"bar_m", 0.0}, {"max_speed_m_per_s", 1.0}}}};
  EXPECT_THAT(error_of(doc), HasSubstr("learning.early_end.bar_m"));
}

// How a robot is learned is not the model: policies and checkpoints keep their robot.
TEST(Learning, TheHashIgnoresHowTheRobotIsLearned) {
  json doc = robot_json("superball");
  doc.erase("learning");
  const Robot a = parse_robot(doc.dump());
  doc["learning"] = {{"time_step_s", 0.003}, {"early_end", {{"bar_m", 5.0}, {"max_speed_m_per_s", 1.0}}}};
  const Robot b = parse_robot(doc.dump());
  EXPECT_EQ(a.hash, b.hash);
  EXPECT_EQ(b.learning_time_step_s, 0.003);
}

Policy shipped_gait(const Robot& robot) {
  const auto file = default_robot_path().parent_path().parent_path() / "policies" / "superball-paper-t4-n5.json";
  return load_policy(file, robot);
}

EpisodeResult play(const Robot& robot, const Policy& policy, double duration_s, const EarlyEnd& rule) {
  CoreController controller(robot, policy);
  EpisodeOptions options;
  options.duration_s = duration_s;
  options.early_end = rule;
  return run_episode(robot, controller, options);
}

// A team that holds every cable at its starting length, so that the robot stays
// where it settled.
Policy standing(const Robot& robot) {
  evolve::Team team;
  team.rest_lengths_m.assign(robot.cables.size(), std::vector<double>(3, robot.initial_rest_length_m));
  return evolve::team_policy(robot, 1.0, 3, team);
}

// A team ended early is the same episode cut short: its distance is the full
// episode's at that time, bit for bit; and it ends at the first whole second from
// which even the bound's speed cannot reach the bar.
TEST(Learning, AnEpisodeEndsAtTheFirstSecondItCannotReachTheBar) {
  const Robot robot = load_robot(default_robot_path());
  const Policy gait = standing(robot);
  // Standing still, 0.5 m/s for the rest of 10 s is short of 3 m after 4 s.
  const EarlyEnd rule{3.0, 0.5};
  const double duration_s = 10.0;
  const EpisodeResult cut = play(robot, gait, duration_s, rule);
  ASSERT_TRUE(cut.ended_early);
  ASSERT_TRUE(cut.feasible);
  EXPECT_LT(cut.sim_time_s, duration_s);
  const EpisodeResult same = play(robot, gait, cut.sim_time_s, {});
  EXPECT_FALSE(same.ended_early);
  EXPECT_EQ(same.distance_m, cut.distance_m);
  EXPECT_LT(cut.distance_m + rule.max_speed_m_per_s * (duration_s - cut.sim_time_s), rule.bar_m);
  // One second earlier the bar was still within reach.
  const EpisodeResult before = play(robot, gait, cut.sim_time_s - 1.0, {});
  EXPECT_GE(before.distance_m + rule.max_speed_m_per_s * (duration_s - cut.sim_time_s + 1.0), rule.bar_m);
}

// A bar out of reach of the whole episode (a short one) would end every episode at
// its first second: the episode runs to its end instead, as without the rule.
TEST(Learning, AnEpisodeTooShortToReachTheBarRunsToItsEnd) {
  const Robot robot = load_robot(default_robot_path());
  const Policy gait = standing(robot);
  const EarlyEnd rule{3.0, 0.5};  // 3 m needs 6 s at 0.5 m/s
  const EpisodeResult short_one = play(robot, gait, 5.0, rule);
  EXPECT_FALSE(short_one.ended_early);
  EXPECT_EQ(short_one.sim_time_s, play(robot, gait, 5.0, {}).sim_time_s);
  EXPECT_TRUE(play(robot, gait, 7.0, rule).ended_early);
}

// The default robot's gait rolls past its bar: the rule never touches it.
TEST(Learning, AGaitThatReachesTheBarRunsToItsEndUnchanged) {
  const Robot robot = load_robot(default_robot_path());
  const Policy gait = shipped_gait(robot);
  const EarlyEnd rule{robot.early_end_bar_m, robot.early_end_max_speed_m_per_s};
  const EpisodeResult with = play(robot, gait, 60.0, rule);
  const EpisodeResult without = play(robot, gait, 60.0, {});
  EXPECT_FALSE(with.ended_early);
  EXPECT_EQ(with.sim_time_s, without.sim_time_s);
  EXPECT_EQ(with.distance_m, without.distance_m);
  EXPECT_GT(with.distance_m, rule.bar_m);
}

TEST(Learning, AnEndedTeamScoresItsPaceOverTheWholeEpisodeAtMostTheBar) {
  EpisodeResult r;
  r.ended_early = true;
  r.sim_time_s = 30.0;
  r.distance_m = 4.0;
  EXPECT_DOUBLE_EQ(evolve::early_end_score_m(r, 60.0, 20.0), 8.0);
  r.distance_m = 15.0;
  EXPECT_DOUBLE_EQ(evolve::early_end_score_m(r, 60.0, 20.0), 20.0);
  r.sim_time_s = 0.0;
  EXPECT_DOUBLE_EQ(evolve::early_end_score_m(r, 60.0, 20.0), 0.0);
}

}  // namespace
}  // namespace tensegrity::sim
