// SPDX-License-Identifier: Apache-2.0
// `tensegrity drive`: steer through a course of waypoints (ground/drive/), here the
// in-process model (--sim).
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "cli/drive_sim.hpp"
#include "cli/episode_cli.hpp"
#include "cli/shipped_policy.hpp"
#include "robot/symmetry.hpp"
#include "sim/model/episode.hpp"
#include "sim/model/model.hpp"

namespace tensegrity::cli {
namespace {

struct DriveArgs {
  std::vector<std::string> to;
  double within_m = 1.5;
  bool sim = false;
  std::string robot;
  std::string gaits;
  std::uint64_t seed = 1;
  double time_limit_s = 0.0;
  bool json = false;
  std::string record;
};

// "X,Y" in metres; errors name the flag and which --to it was.
Eigen::Vector2d parse_waypoint(const std::string& text, std::size_t index) {
  const std::string field = "--to #" + std::to_string(index + 1) + " (\"" + text + "\")";
  const auto comma = text.find(',');
  if (comma == std::string::npos) throw CommandError(ExitCode::usage, "drive: " + field + ": expected X,Y in metres");
  Eigen::Vector2d w;
  for (int k = 0; k < 2; ++k) {
    const std::string part = k == 0 ? text.substr(0, comma) : text.substr(comma + 1);
    std::size_t used = 0;
    try {
      w[k] = std::stod(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != part.size() || !std::isfinite(w[k]) || std::abs(w[k]) > 1e4) {
      throw CommandError(ExitCode::usage,
                         "drive: " + field + ": " + (k == 0 ? "X" : "Y") + " is not a number of metres within 10 km");
    }
  }
  return w;
}

// The shipped policy's images under every symmetry, each with the heading the symmetry
// carries the policy's recorded heading to (no episode is played).
sim::GaitSet symmetry_gait_set(const sim::Robot& robot, const std::string& policy_path) {
  const sim::Policy source = sim::load_policy(policy_path, robot);
  if (!source.provenance.heading_deg) {
    throw CommandError(ExitCode::usage,
                       "drive: " + policy_path + " records no heading (provenance.gait.heading_deg); give --gaits");
  }
  const auto group = sim::symmetry_group(robot);
  const auto faces = sim::hull_faces(robot);
  sim::Model model(robot, robot.time_step_s);
  model.restore(sim::settled_state(robot, robot.time_step_s));
  const auto nodes = model.node_positions();
  const int start = sim::start_frame(robot, faces, nodes).face;
  if (start < 0) throw CommandError(ExitCode::failure, "drive: the robot's hull has no faces to stand on");
  const double h = *source.provenance.heading_deg * std::numbers::pi / 180.0;
  sim::GaitSet set{robot.name, robot.hash, policy_path, 60.0, {}};
  for (const sim::Symmetry& s : group) {
    sim::Gait g;
    g.name = s.name;
    g.symmetry = s.name;
    g.policy = sim::image_of(source, s, robot);
    g.face = faces[sim::face_image(s, faces, start)].nodes;
    const Eigen::Vector2d d = sim::heading_map(s, faces, start) * Eigen::Vector2d(std::cos(h), std::sin(h));
    g.heading_deg = sim::wrap_deg(std::atan2(d.y(), d.x()) * 180.0 / std::numbers::pi);
    g.speed_m_per_min = source.provenance.score_m;
    set.gaits.push_back(std::move(g));
  }
  return set;
}

void print_progress(const DriveProgress& p, std::size_t waypoints) {
  if (p.waypoint >= waypoints) return;
  std::printf("t %6.1f s  at (%+6.2f, %+6.2f) m  waypoint %zu/%zu %5.1f m away  face %-8s gait %s%s\n", p.time_s,
              p.estimate_m.x(), p.estimate_m.y(), p.waypoint + 1, waypoints, p.distance_m, p.face.c_str(),
              p.gait.c_str(), p.switched ? " (switch)" : "");
  std::fflush(stdout);
}

nlohmann::json outcome_json(const DriveOutcome& o, const DriveArgs& args, const sim::Robot& robot) {
  nlohmann::json wps = nlohmann::json::array();
  int reached = 0;
  for (const auto& w : o.waypoints) {
    reached += w.reached ? 1 : 0;
    // A waypoint the steering never got to has no closest approach: null.
    const bool steered = w.miss_m < 1e299;
    wps.push_back({{"to", {w.target_m.x(), w.target_m.y()}},
                   {"reached", w.reached},
                   {"time_s", steered ? nlohmann::json(w.time_s) : nlohmann::json()},
                   {"miss_m", steered ? nlohmann::json(w.miss_m) : nlohmann::json()}});
  }
  return {{"robot", robot.name},
          {"seed", args.seed},
          {"within_m", args.within_m},
          {"waypoints", wps},
          {"reached", reached},
          {"completed", o.completed},
          {"time_s", o.time_s},
          {"periods", o.periods},
          {"switches", o.switches},
          {"face_changes", o.face_changes},
          {"cutoff_steps", o.cutoff_steps},
          {"cutoff_steps_after_switch", o.cutoff_steps_after_switch},
          {"faults", o.faults},
          {"hard_limit_steps", o.hard_limit_steps},
          {"stopped_by", o.stopped_by}};
}

void run_drive(const DriveArgs& args) {
  if (!args.sim) {
    throw CommandError(ExitCode::usage,
                       "drive: only --sim (the in-process model) is available; the end caps over DDS are not yet");
  }
  const std::string policy = args.gaits.empty() ? shipped_policy_or("").string() : "";
  const sim::Robot robot = load_robot_arg(args.robot, policy);
  const sim::GaitSet set =
      args.gaits.empty() ? symmetry_gait_set(robot, policy) : sim::load_gait_set(args.gaits, robot);
  DriveSimOptions options;
  for (std::size_t i = 0; i < args.to.size(); ++i) options.waypoints_m.push_back(parse_waypoint(args.to[i], i));
  options.within_m = args.within_m;
  options.seed = args.seed;
  options.time_limit_s = args.time_limit_s;
  options.record = args.record;
  const std::size_t n = options.waypoints_m.size();
  if (!args.json) {
    std::printf("robot %s, %zu gaits (%s), %zu waypoints within %.2f m, seed %llu\n", robot.name.c_str(),
                set.gaits.size(), args.gaits.empty() ? "the shipped policy's symmetry images" : args.gaits.c_str(), n,
                args.within_m, static_cast<unsigned long long>(args.seed));
  }
  const DriveOutcome o = drive_sim(robot, set, options, [&](const DriveProgress& p) {
    if (!args.json) print_progress(p, n);
  });
  if (args.json) {
    std::printf("%s\n", outcome_json(o, args, robot).dump(2).c_str());
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      const auto& w = o.waypoints[i];
      if (w.miss_m >= 1e299) {
        std::printf("waypoint %zu (%+.2f, %+.2f): not steered to\n", i + 1, w.target_m.x(), w.target_m.y());
        continue;
      }
      std::printf("waypoint %zu (%+.2f, %+.2f): %s, closest %.2f m at %.1f s\n", i + 1, w.target_m.x(), w.target_m.y(),
                  w.reached ? "reached" : "missed", w.miss_m, w.time_s);
    }
    std::printf(
        "%s after %.1f s of physics: %d switches, %ld cut-off steps (%ld in a period after a switch), %d "
        "faults, %d steps above the hard limit%s%s\n",
        o.completed ? "course done" : "course not done", o.time_s, o.switches, o.cutoff_steps,
        o.cutoff_steps_after_switch, o.faults, o.hard_limit_steps,
        o.stopped_by.empty() ? "" : "; stopped: ", o.stopped_by.c_str());
  }
  bool all = o.completed;
  for (const auto& w : o.waypoints) all = all && w.reached;
  if (!all) throw CommandError(ExitCode::failure, "drive: the course was not completed");
}

}  // namespace

void add_drive_command(CLI::App& app) {
  auto args = std::make_shared<DriveArgs>();
  CLI::App* cmd = app.add_subcommand(
      "drive",
      "Steer through a course of waypoints by switching gaits at period boundaries. Waypoints are X,Y in metres, "
      "world frame, relative to the settled start's end-cap centre; position and heading are estimated only from "
      "the end caps' accelerometers and a position fix (1 Hz, 0.1 m noise)");
  cmd->add_option("--to", args->to, "Waypoint X,Y in metres (repeat for a course, driven in order)")
      ->required()
      ->allow_extra_args(false);
  cmd->add_option("--within", args->within_m, "A waypoint is reached this near, metres")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 100.0));
  cmd->add_flag("--sim", args->sim, "Drive the in-process model (its sensors emulated, with seeded noise)");
  cmd->add_option("--robot", args->robot, "Robot description (default: robots/superball-paper.json)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--gaits", args->gaits,
                  "Gait set file (tensegrity-gait-set/1; default: the shipped policy's symmetry images, with the "
                  "headings the symmetries carry its own to)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--seed", args->seed, "Seed of the sensors' noise")->capture_default_str();
  cmd->add_option("--time-limit", args->time_limit_s, "Physics time allowed, seconds (default: 90 per waypoint)")
      ->check(CLI::Range(1.0, 86400.0));
  cmd->add_flag("--json", args->json, "Print one JSON object: each waypoint's reached, time_s, miss_m, and totals");
  cmd->add_option("--record", args->record, "Write the path (true and estimated, 10 Hz) to this CSV file");
  cmd->callback([args] { run_drive(*args); });
}

}  // namespace tensegrity::cli
