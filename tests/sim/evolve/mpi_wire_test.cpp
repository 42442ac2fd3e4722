// SPDX-License-Identifier: Apache-2.0
// The messages of an MPI run, without MPI: every field survives the trip, doubles
// bit for bit (a score must not change on its way to rank 0), and damaged bytes are
// reported rather than trusted. The episode setup rebuilds on a rank the scorer rank
// 0 uses, giving the same scores.
#include "sim/evolve/mpi_wire.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "sim/evolve/episode_evaluator.hpp"
#include "sim/evolve/episode_setup.hpp"
#include "robot/robot.hpp"

namespace tensegrity::sim::evolve {
namespace {

std::uint64_t bits(double v) { return std::bit_cast<std::uint64_t>(v); }

// Values whose bits an encoding through text or float could change.
const std::vector<double> kAwkward = {0.1,
                                      -0.0,
                                      std::numeric_limits<double>::denorm_min(),
                                      std::numeric_limits<double>::max(),
                                      std::numeric_limits<double>::infinity(),
                                      std::bit_cast<double>(std::uint64_t{0x7ff8000000000abcULL}),  // NaN payload
                                      1.0 / 3.0};

TEST(MpiWire, JobKeepsEveryValueBitForBit) {
  wire::Job job;
  job.batch = 7;
  job.index = (std::uint64_t{1} << 40) + 3;
  job.team.rest_lengths_m = {kAwkward, {}, {0.6, 1.1}};
  const wire::Job back = wire::decode_job(wire::encode(job));
  EXPECT_EQ(back.batch, job.batch);
  EXPECT_EQ(back.index, job.index);
  ASSERT_EQ(back.team.rest_lengths_m.size(), 3u);
  for (std::size_t c = 0; c < 3; ++c) {
    ASSERT_EQ(back.team.rest_lengths_m[c].size(), job.team.rest_lengths_m[c].size());
    for (std::size_t j = 0; j < job.team.rest_lengths_m[c].size(); ++j) {
      EXPECT_EQ(bits(back.team.rest_lengths_m[c][j]), bits(job.team.rest_lengths_m[c][j]));
    }
  }
}

TEST(MpiWire, ResultKeepsScoreBitsFeasibilityAndError) {
  for (double score : kAwkward) {
    const wire::Result r{3, 4, TeamResult{score, false}, "ODE error 2: boom"};
    const wire::Result back = wire::decode_result(wire::encode(r));
    EXPECT_EQ(back.batch, 3u);
    EXPECT_EQ(back.index, 4u);
    EXPECT_EQ(bits(back.result.score_m), bits(score));
    EXPECT_FALSE(back.result.feasible);
    EXPECT_EQ(back.error, r.error);
  }
  EXPECT_TRUE(wire::decode_result(wire::encode(wire::Result{1, 0, TeamResult{1.5, true}, {}})).result.feasible);
}

TEST(MpiWire, SetupAndHelloRoundTrip) {
  const std::string payload("bytes\0with a zero", 17);
  const wire::Setup setup = wire::decode_setup(wire::encode(wire::Setup{wire::kProtocol, "kind/1", payload}));
  EXPECT_EQ(setup.protocol, wire::kProtocol);
  EXPECT_EQ(setup.kind, "kind/1");
  EXPECT_EQ(setup.payload, payload);
  const wire::Hello hello = wire::decode_hello(wire::encode(wire::Hello{9, 12, "node-3", "gcc", "no robot"}));
  EXPECT_EQ(hello.protocol, 9u);
  EXPECT_EQ(hello.threads, 12);
  EXPECT_EQ(hello.host, "node-3");
  EXPECT_EQ(hello.build, "gcc");
  EXPECT_EQ(hello.error, "no robot");
}

TEST(MpiWire, DamagedBytesAreRefused) {
  wire::Job job{1, 2, Team{{{0.7, 0.8}, {0.9}}}};
  const wire::Bytes good = wire::encode(job);
  for (std::size_t n = 0; n < good.size(); ++n) {
    EXPECT_THROW((void)wire::decode_job(wire::Bytes(good.begin(), good.begin() + static_cast<long>(n))),
                 wire::WireError)
        << n << " bytes";
  }
  wire::Bytes longer = good;
  longer.push_back(0);
  EXPECT_THROW((void)wire::decode_job(longer), wire::WireError);
  // A huge count is refused before anything is allocated for it.
  wire::Writer w;
  w.u64(1);
  w.u64(2);
  w.u64(std::uint64_t{1} << 60);
  EXPECT_THROW((void)wire::decode_job(w.take()), wire::WireError);
  wire::Bytes result = wire::encode(wire::Result{1, 2, TeamResult{}, {}});
  result[8 + 8 + 8] = 2;  // the feasible flag
  EXPECT_THROW((void)wire::decode_result(result), wire::WireError);
}

std::string robot_text() {
  std::ifstream in(robot_path_named("superball"), std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

EvolveConfig physics_config(const Robot& robot) {
  EvolveConfig c;
  c.complexity = 3;
  c.period_s = 1.0;
  c.duration_s = 1.0;
  set_robot(c, robot);
  return c;
}

TEST(EpisodeSetup, RoundTripsAndScoresLikeRankZero) {
  const std::string text = robot_text();
  const Robot robot = parse_robot(text);
  EvolveConfig config = physics_config(robot);
  config.dt_s = 0.002;
  const EpisodeSetup sent = episode_setup(text, config);
  const EpisodeSetup got = episode_setup_from_wire(wire::decode_setup(wire::encode(to_wire(sent))));
  EXPECT_EQ(got.robot_json, text);
  EXPECT_EQ(got.robot_hash, robot.hash);
  EXPECT_EQ(got.cables, config.cables);
  EXPECT_EQ(bits(got.period_s), bits(config.period_s));
  EXPECT_EQ(got.complexity, config.complexity);
  EXPECT_EQ(bits(got.duration_s), bits(config.duration_s));
  EXPECT_EQ(bits(got.dt_s), bits(config.dt_s));

  Team team;
  for (int c = 0; c < config.cables; ++c) team.rest_lengths_m.push_back({0.8, 0.95 - 0.005 * c, 0.7});
  const TeamResult here = episode_team_function(robot, config)(team);
  const TeamResult there = episode_team_function(got)(team);
  EXPECT_EQ(bits(there.score_m), bits(here.score_m));
  EXPECT_EQ(there.feasible, here.feasible);
  EvolveConfig robot_step = config;
  robot_step.dt_s = 0.0;
  EXPECT_NE(bits(episode_team_function(robot, robot_step)(team).score_m), bits(here.score_m))
      << "the team was not scored at the config's step";
}

TEST(EpisodeSetup, ForeignRobotOrKindIsRefused) {
  const std::string text = robot_text();
  const Robot robot = parse_robot(text);
  EvolveConfig config = physics_config(robot);
  config.robot_hash = "0123456789abcdef";
  EXPECT_THROW((void)episode_setup(text, config), ConfigError);
  wire::Setup other = to_wire(episode_setup(text, physics_config(robot)));
  other.kind = "something-else/1";
  EXPECT_THROW((void)episode_setup_from_wire(other), wire::WireError);
  other = to_wire(episode_setup(text, physics_config(robot)));
  other.payload.pop_back();
  EXPECT_THROW((void)episode_setup_from_wire(other), wire::WireError);
}

}  // namespace
}  // namespace tensegrity::sim::evolve
