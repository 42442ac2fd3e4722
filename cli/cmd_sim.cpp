// SPDX-License-Identifier: Apache-2.0
// `tensegrity sim`: one episode, a readable summary or one JSON object.
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "cli/commands.hpp"
#include "cli/episode_cli.hpp"
#include "sim/model/benchmark_policy.hpp"
#include "sim/model/episode.hpp"

namespace tensegrity::cli {
namespace {

struct SimArgs {
  std::string robot;
  std::string policy;
  bool benchmark_policy = false;
  double duration_s = 60.0;
  double dt_s = 0.0;
  std::string telemetry;
  int telemetry_every = 1;
  std::string start = "settled";
  bool start_given = false;
  bool json = false;
  std::string first;  // played for first_s before --policy
  double first_s = 0.0;
};

// The drop start lets the description's pose fall; the settled start lets the pose the
// robot file chose fall and scores from where it lies, so the pose is named. The
// names are the robot file's `start.pose` values.
nlohmann::json start_json(const sim::Robot& robot, sim::StartKind kind) {
  if (kind == sim::StartKind::drop) return {{"kind", "drop"}, {"pose", "description"}};
  const bool face_down = robot.start_pose == sim::Robot::StartPose::face_down;
  return {{"kind", "settled"}, {"pose", face_down ? "face_down" : "description"}, {"settle_s", robot.settle_s}};
}

std::string start_text(const sim::Robot& robot, sim::StartKind kind) {
  if (kind == sim::StartKind::drop) return "drop start from the description's pose";
  const char* pose =
      robot.start_pose == sim::Robot::StartPose::face_down ? "a cable triangle face down" : "the description's pose";
  char text[128];
  std::snprintf(text, sizeof text, "settled start (%s, %.3g s)", pose, robot.settle_s);
  return text;
}

void run_sim(const SimArgs& args) {
  const sim::Robot robot = load_robot_arg(args.robot, args.policy);
  std::unique_ptr<sim::Controller> controller;
  std::string controller_name;
  sim::EpisodeOptions options;
  options.duration_s = args.duration_s;
  options.dt_s = args.dt_s;
  if (!args.policy.empty()) {
    controller = make_policy_controller(robot, args.policy);
    controller_name = args.policy;
  } else {
    controller = std::make_unique<sim::BenchmarkController>();
    controller_name = "benchmark policy";
  }
  options.start = args.start == "drop" ? sim::StartKind::drop : sim::StartKind::settled;
  // The benchmark's defined start, unless the user chose one.
  if (args.policy.empty() && !args.start_given) options.start = sim::StartKind::drop;
  std::unique_ptr<sim::CsvTelemetry> telemetry;
  if (!args.telemetry.empty()) {
    telemetry = std::make_unique<sim::CsvTelemetry>(args.telemetry);
    options.telemetry = telemetry.get();
    options.telemetry_every = args.telemetry_every;
  }
  sim::ModelState after_first;
  if (!args.first.empty()) {
    // As the end caps swap tables at a period boundary: the first policy rolls the robot
    // from the start, and the episode reported is --policy from where it left it.
    const auto first = make_policy_controller(robot, args.first);
    sim::EpisodeOptions lead = options;
    lead.duration_s = args.first_s;
    lead.telemetry = nullptr;
    lead.end_state = &after_first;
    const sim::EpisodeResult r = sim::run_episode(robot, *first, lead);
    if (!r.feasible)
      throw CommandError(ExitCode::failure, "sim: --first " + args.first + " is infeasible: " + r.infeasible_reason);
    options.start_state = &after_first;
    char after[64];
    std::snprintf(after, sizeof after, " for %.4g s, then ", args.first_s);
    controller_name = args.first + after + controller_name;
  }
  const sim::EpisodeResult result = sim::run_episode(robot, *controller, options);
  if (args.json) {
    nlohmann::json j = episode_json(result);
    j["robot"] = robot.name;
    j["robot_hash"] = robot.hash;
    j["controller"] = controller_name;
    if (!args.first.empty()) j["first"] = {{"policy", args.first}, {"duration_s", args.first_s}};
    j["start"] = start_json(robot, options.start);
    j["dt_s"] = options.dt_s > 0 ? options.dt_s : robot.time_step_s;
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("robot %s (%s), %s, %.1f s at dt %.4g s, %s\n", robot.name.c_str(), robot.hash.c_str(),
                controller_name.c_str(), args.duration_s, options.dt_s > 0 ? options.dt_s : robot.time_step_s,
                start_text(robot, options.start).c_str());
    print_episode_summary(result);
  }
}

}  // namespace

void add_sim_command(CLI::App& app) {
  auto args = std::make_shared<SimArgs>();
  CLI::App* cmd = app.add_subcommand("sim", "Run one episode of the robot model and summarise it");
  cmd->add_option("--robot", args->robot,
                  "Robot description (default: the one the policy names, else robots/superball-paper.json)")
      ->check(CLI::ExistingFile);
  auto* policy =
      cmd->add_option("--policy", args->policy, "Policy file to play (tensegrity-policy/1)")->check(CLI::ExistingFile);
  cmd->add_flag("--benchmark-policy", args->benchmark_policy,
                "Play the fixed benchmark policy (the default without --policy)")
      ->excludes(policy);
  cmd->add_option("--duration", args->duration_s, "Episode length, seconds")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 86400.0));
  cmd->add_option("--dt", args->dt_s, "Time step, seconds (default: the robot's)")->check(CLI::Range(1e-5, 0.01));
  auto* start = cmd->add_option("--start", args->start,
                                "Start: settled (at rest on the ground; default with --policy) or drop "
                                "(the benchmark's start; default without)")
                    ->check(CLI::IsMember({"settled", "drop"}));
  cmd->add_option("--telemetry", args->telemetry, "Run record CSV, one row per recorded step (as hil --record)");
  cmd->add_option("--telemetry-every", args->telemetry_every, "Record every N-th step")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--json", args->json, "Print one JSON object instead of the summary");
  auto* first = cmd->add_option("--first", args->first,
                                "Play this policy first, for --first-s seconds from the start; the episode reported is "
                                "--policy from where it left the robot (a gait switch at a period boundary)")
                    ->check(CLI::ExistingFile)
                    ->needs(policy);
  cmd->add_option("--first-s", args->first_s, "With --first: how long it plays, seconds")
      ->check(CLI::Range(0.0, 86400.0))
      ->needs(first);
  cmd->callback([args, start] {
    args->start_given = start->count() > 0;
    run_sim(*args);
  });
}

}  // namespace tensegrity::cli
