// SPDX-License-Identifier: Apache-2.0
// `tensegrity robustness POLICY`: the gait played across a perturbation set (motors,
// cables, masses, ground, sensors, actuation, engine, start), each case's distance
// and retention, and the worst case (docs/design/robustness.md).
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "cli/commands.hpp"
#include "cli/episode_cli.hpp"
#include "sim/model/episode_json.hpp"
#include "robot/perturbation_set.hpp"
#include "robot/policy.hpp"
#include "sim/analysis/robustness.hpp"

namespace tensegrity::cli {
namespace {

// The set shipped with the documentation (docs/design/robustness.md says why each range).
constexpr const char* kDefaultSet = "docs/design/robustness-set.json";

struct RobustnessArgs {
  std::string policy;
  std::string robot;
  std::string set;
  bool json = false;
  double duration_s = 60.0;
  int threads = 0;
};

std::filesystem::path set_path(const std::string& given) {
  if (!given.empty()) return given;
  if (std::filesystem::exists(kDefaultSet)) return kDefaultSet;
#ifdef TENSEGRITY_SOURCE_DIR
  const std::filesystem::path in_source = std::filesystem::path(TENSEGRITY_SOURCE_DIR) / kDefaultSet;
  if (std::filesystem::exists(in_source)) return in_source;
#endif
  throw CommandError(ExitCode::usage,
                     std::string("robustness: no perturbation set: ") + kDefaultSet + " not found; give --set FILE");
}

nlohmann::json case_json(const sim::RobustnessCase& c) {
  nlohmann::json j = {{"name", c.name}, {"robot_hash", c.robot_hash}};
  if (!c.error.empty()) {
    j["error"] = c.error;
    return j;
  }
  j["distance_m"] = c.episode.distance_m;
  j["retention"] = c.retention;
  j["uphill_m"] = c.uphill_m ? nlohmann::json(*c.uphill_m) : nlohmann::json(nullptr);
  j["episode"] = episode_json(c.episode);
  return j;
}

void print_json(const RobustnessArgs& args, const std::filesystem::path& set, const sim::Robot& robot,
                const sim::RobustnessReport& report) {
  nlohmann::json cases = nlohmann::json::array();
  for (const auto& c : report.cases) cases.push_back(case_json(c));
  nlohmann::json j = {{"format", "tensegrity-robustness/1"},
                      {"policy", args.policy},
                      {"robot", robot.name},
                      {"robot_hash", robot.hash},
                      {"set", set.string()},
                      {"duration_s", args.duration_s},
                      {"nominal", episode_json(report.nominal)},
                      {"travel_azimuth_deg", report.travel_azimuth_deg},
                      {"cases", cases}};
  if (report.worst >= 0) {
    const auto& w = report.cases[report.worst];
    j["worst"] = {{"name", w.name}, {"retention", w.retention}, {"distance_m", w.episode.distance_m}};
  }
  std::printf("%s\n", j.dump(2).c_str());
}

void print_text(const RobustnessArgs& args, const std::filesystem::path& set, const sim::Robot& robot,
                const sim::RobustnessReport& report) {
  std::printf("%s on %s (%s), %.1f s per case, set %s\n", args.policy.c_str(), robot.name.c_str(), robot.hash.c_str(),
              args.duration_s, set.string().c_str());
  std::printf("  %-36s %11s %9s %9s\n", "case", "distance_m", "retained", "uphill_m");
  std::printf("  %-36s %11.3f %9.3f\n", "nominal", report.nominal.distance_m,
              report.nominal.distance_m > 0 ? 1.0 : 0.0);
  for (const auto& c : report.cases) {
    if (!c.error.empty()) {
      std::printf("  %-36s not played: %s\n", c.name.c_str(), c.error.c_str());
      continue;
    }
    std::printf("  %-36s %11.3f %9.3f", c.name.c_str(), c.episode.distance_m, c.retention);
    if (c.uphill_m) std::printf(" %9.3f", *c.uphill_m);
    if (!c.episode.feasible) std::printf("  infeasible: %s", c.episode.infeasible_reason.c_str());
    std::printf("\n");
  }
  if (report.worst >= 0) {
    const auto& w = report.cases[report.worst];
    std::printf("worst: %s, %.3f m, %.3f of nominal\n", w.name.c_str(), w.episode.distance_m, w.retention);
  }
}

void run_robustness(RobustnessArgs args) {
  const sim::Robot robot = load_robot_arg(args.robot, args.policy);
  const sim::Policy policy = sim::load_policy(args.policy, robot);
  const std::filesystem::path set_file = set_path(args.set);
  const sim::PerturbationSet set = sim::load_perturbation_set(set_file);
  if (args.threads <= 0) args.threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const sim::RobustnessReport report =
      sim::run_robustness(robot, policy, set, sim::RobustnessOptions{args.duration_s, args.threads});
  if (!report.nominal.feasible) {
    throw CommandError(ExitCode::failure,
                       "robustness: the gait is infeasible on the robot itself: " + report.nominal.infeasible_reason);
  }
  if (args.json) {
    print_json(args, set_file, robot, report);
  } else {
    print_text(args, set_file, robot, report);
  }
}

}  // namespace

void add_robustness_command(CLI::App& app) {
  auto args = std::make_shared<RobustnessArgs>();
  CLI::App* cmd = app.add_subcommand("robustness", "Play a gait across a perturbation set: distance and retention");
  cmd->add_option("POLICY", args->policy, "Policy file to play (tensegrity-policy/1)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--robot", args->robot, "Robot description (default: the one the policy names)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--set", args->set,
                  std::string("Perturbation set (tensegrity-perturbation-set/1; default ") + kDefaultSet + ")")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--json", args->json, "Print one JSON object instead of the table");
  cmd->add_option("--duration", args->duration_s, "Episode length per case, seconds")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 86400.0));
  cmd->add_option("--threads", args->threads, "Cases played at once (default: the machine's cores)")
      ->check(CLI::Range(1, 1024));
  cmd->callback([args] { run_robustness(*args); });
}

}  // namespace tensegrity::cli
