// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/episode_setup.hpp"

#include "sim/evolve/episode_evaluator.hpp"

namespace tensegrity::sim::evolve {
namespace {

Robot parse_checked(const EpisodeSetup& setup) {
  Robot robot = parse_robot(setup.robot_json, "robot sent by rank 0");
  if (robot.hash != setup.robot_hash) {
    throw ConfigError("robot description hashes to " + robot.hash + ", expected " + setup.robot_hash);
  }
  return robot;
}

}  // namespace

EpisodeSetup episode_setup(const std::string& robot_json, const EvolveConfig& config) {
  // The setup carries no randomization: ranks would score the robot's own model.
  if (!config.randomization.empty()) {
    throw ConfigError("randomized models (--randomize) are not sent to MPI ranks: run without --mpi");
  }
  EpisodeSetup setup{robot_json,      config.robot_hash,      config.cables,
                     config.period_s, config.complexity,      config.duration_s,
                     config.dt_s,     config.early_end_bar_m, config.early_end_speed_m_per_s};
  // Fail on rank 0, before anything is sent, when the text is not the config's robot.
  (void)parse_checked(setup);
  return setup;
}

wire::Setup to_wire(const EpisodeSetup& setup) {
  wire::Writer w;
  w.str(setup.robot_json);
  w.str(setup.robot_hash);
  w.u32(static_cast<std::uint32_t>(setup.cables));
  w.f64(setup.period_s);
  w.u32(static_cast<std::uint32_t>(setup.complexity));
  w.f64(setup.duration_s);
  w.f64(setup.dt_s);
  w.f64(setup.early_end_bar_m);
  w.f64(setup.early_end_speed_m_per_s);
  const wire::Bytes bytes = w.take();
  return wire::Setup{wire::kProtocol, kEpisodeSetupKind, std::string(bytes.begin(), bytes.end())};
}

EpisodeSetup episode_setup_from_wire(const wire::Setup& setup) {
  if (setup.kind != kEpisodeSetupKind) {
    throw wire::WireError("setup of kind '" + setup.kind + "', expected '" + kEpisodeSetupKind + "'");
  }
  try {
    wire::Reader r(reinterpret_cast<const unsigned char*>(setup.payload.data()), setup.payload.size());
    EpisodeSetup s;
    s.robot_json = r.str();
    s.robot_hash = r.str();
    s.cables = static_cast<int>(r.u32());
    s.period_s = r.f64();
    s.complexity = static_cast<int>(r.u32());
    s.duration_s = r.f64();
    s.dt_s = r.f64();
    s.early_end_bar_m = r.f64();
    s.early_end_speed_m_per_s = r.f64();
    r.finish();
    return s;
  } catch (const wire::WireError& e) {
    throw wire::WireError(std::string("episode setup: ") + e.what());
  }
}

TeamFunction episode_team_function(const EpisodeSetup& setup) {
  const Robot robot = parse_checked(setup);
  // Only the fields evaluate_team reads; validate() guards them like on rank 0.
  EvolveConfig config;
  config.cables = setup.cables;
  config.period_s = setup.period_s;
  config.complexity = setup.complexity;
  config.duration_s = setup.duration_s;
  config.dt_s = setup.dt_s;
  config.early_end_bar_m = setup.early_end_bar_m;
  config.early_end_speed_m_per_s = setup.early_end_speed_m_per_s;
  validate(config);
  return episode_team_function(robot, config);
}

}  // namespace tensegrity::sim::evolve
