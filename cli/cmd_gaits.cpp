// SPDX-License-Identifier: Apache-2.0
// `tensegrity gaits`: the robot's symmetries (`symmetries`), a policy's image under one
// (`transform`) and the gait set a policy and the symmetry group give (`set`).
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "cli/episode_cli.hpp"
#include "sim/model/core_controller.hpp"
#include "sim/model/episode.hpp"
#include "robot/gait_set.hpp"
#include "robot/symmetry.hpp"

namespace tensegrity::cli {
namespace {

struct GaitsArgs {
  std::string robot;
  std::string policy;
  std::string symmetry;
  std::string out;
  double duration_s = 60.0;
  bool measure = true;
  bool json = false;
};

double deg(double rad) { return rad * 180.0 / std::numbers::pi; }

// What a 2-D isometry does to a heading, in words and as JSON: a turn by an angle, or
// a mirror across the line at an angle (headings h go to 2 * axis - h).
nlohmann::json isometry_json(const Eigen::Matrix2d& a) {
  if (a.determinant() > 0.0) return {{"kind", "turn"}, {"deg", sim::wrap_deg(deg(std::atan2(a(1, 0), a(0, 0))))}};
  return {{"kind", "mirror"}, {"axis_deg", sim::wrap_deg(deg(std::atan2(a(1, 0), a(0, 0))) / 2.0)}};
}

std::string isometry_text(const Eigen::Matrix2d& a) {
  const nlohmann::json j = isometry_json(a);
  char text[64];
  if (j["kind"] == "turn") {
    std::snprintf(text, sizeof text, "turn %+.1f deg", j["deg"].get<double>());
  } else {
    std::snprintf(text, sizeof text, "mirror about %+.1f deg", j["axis_deg"].get<double>());
  }
  return text;
}

// The hull face the settled start stands on (an index into `faces`).
int settled_face(const sim::Robot& robot, const std::vector<sim::HullFace>& faces) {
  sim::Model model(robot, robot.time_step_s);
  model.restore(sim::settled_state(robot, robot.time_step_s));
  const std::vector<Eigen::Vector3d> nodes = model.node_positions();
  return sim::start_frame(robot, faces, nodes).face;
}

std::string face_text(const sim::HullFace& f) {
  return std::to_string(f.nodes[0]) + "-" + std::to_string(f.nodes[1]) + "-" + std::to_string(f.nodes[2]) +
         (f.closed ? " (closed)" : " (open)");
}

void run_symmetries(const GaitsArgs& args) {
  const sim::Robot robot = load_robot_arg(args.robot, args.policy);
  const auto group = sim::symmetry_group(robot);
  const auto faces = sim::hull_faces(robot);
  const int start = settled_face(robot, faces);
  if (start < 0) throw CommandError(ExitCode::failure, "gaits: the robot's hull has no faces to stand on");
  nlohmann::json list = nlohmann::json::array();
  for (const sim::Symmetry& s : group) {
    const int image = sim::face_image(s, faces, start);
    const Eigen::Matrix2d a = sim::heading_map(s, faces, start);
    list.push_back({{"name", s.name},
                    {"proper", s.proper()},
                    {"endcaps", s.node_map},
                    {"cables", s.cable_map},
                    {"owners_follow", s.owners_follow},
                    {"start_face_image", faces[image].nodes},
                    {"keeps_start_face", image == start},
                    {"heading_map", isometry_json(a)}});
  }
  if (args.json) {
    const nlohmann::json j = {{"robot", robot.name},        {"robot_hash", robot.hash},
                              {"order", group.size()},      {"start_face", faces[start].nodes},
                              {"hull_faces", faces.size()}, {"symmetries", list}};
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf("robot %s: %zu symmetries; the settled start stands on face %s\n", robot.name.c_str(), group.size(),
              face_text(faces[start]).c_str());
  for (std::size_t k = 0; k < group.size(); ++k) {
    const auto& s = group[k];
    const int image = sim::face_image(s, faces, start);
    std::printf("  %-12s %-10s start face -> %-16s %s%s\n", s.name.c_str(), s.proper() ? "rotation" : "reflection",
                face_text(faces[image]).c_str(), isometry_text(sim::heading_map(s, faces, start)).c_str(),
                image == start ? "  (keeps the start face)" : "");
  }
}

// Plays `policy` from the settled start for duration_s.
sim::EpisodeResult play(const sim::Robot& robot, const sim::Policy& policy, double duration_s) {
  sim::CoreController controller(robot, policy);
  sim::EpisodeOptions options;
  options.duration_s = duration_s;
  return sim::run_episode(robot, controller, options);
}

void record_gait(sim::Policy& policy, const sim::EpisodeResult& r) {
  sim::Provenance& pr = policy.provenance;
  pr.axial_spin_rms_rad_per_s = r.axial_spin_rms_rad_per_s;
  pr.axial_spin_max_rad_per_s = r.axial_spin_max_rad_per_s;
  pr.endcaps_touched_ground = r.endcaps_touched_ground;
  pr.min_strut_gap_m = r.min_strut_gap_m;
  pr.strut_overlap_s = r.strut_overlap_s;
  pr.heading_deg = r.travel.heading_deg;
}

void run_transform(const GaitsArgs& args) {
  const sim::Robot robot = load_robot_arg(args.robot, args.policy);
  const sim::Policy source = sim::load_policy(args.policy, robot);
  const auto group = sim::symmetry_group(robot);
  sim::Policy image = sim::image_of(source, sim::find_symmetry(group, args.symmetry), robot);
  if (args.measure) {
    const sim::EpisodeResult r = play(robot, image, args.duration_s);
    if (!r.feasible)
      throw CommandError(ExitCode::failure, "gaits transform: the image is infeasible: " + r.infeasible_reason);
    record_gait(image, r);
    std::printf("%s from the settled start: %.2f m in %.0f s\n", args.symmetry.c_str(), r.distance_m, args.duration_s);
    print_heading(r.travel, r.start_face);
  }
  sim::save_policy(args.out, image);
  std::printf("wrote %s\n", args.out.c_str());
}

std::array<int, 3> nodes_of(const sim::HullFace& f) { return f.nodes; }

void run_set(const GaitsArgs& args) {
  const sim::Robot robot = load_robot_arg(args.robot, args.policy);
  const sim::Policy source = sim::load_policy(args.policy, robot);
  const auto group = sim::symmetry_group(robot);
  const auto faces = sim::hull_faces(robot);
  const int start = settled_face(robot, faces);
  if (start < 0) throw CommandError(ExitCode::failure, "gaits: the robot's hull has no faces to stand on");
  const sim::EpisodeResult base = play(robot, source, args.duration_s);
  if (!base.feasible || !base.travel.heading_deg) {
    throw CommandError(ExitCode::failure, "gaits set: " + args.policy + " does not roll from the settled start");
  }
  sim::GaitSet set{robot.name, robot.hash, args.policy, args.duration_s, {}};
  for (const sim::Symmetry& s : group) {
    sim::Gait g;
    g.name = s.name;
    g.symmetry = s.name;
    g.policy = sim::image_of(source, s, robot);
    const int image = sim::face_image(s, faces, start);
    g.face = nodes_of(faces[image]);
    // The symmetry carries the source's path to the image face's start frame; from the
    // settled start's own face the gait is played and measured instead.
    sim::EpisodeResult r = base;
    if (image == start && !s.matrix.isIdentity(1e-9)) r = play(robot, g.policy, args.duration_s);
    const Eigen::Vector2d d =
        image == start ? r.travel.start_m : Eigen::Vector2d(sim::heading_map(s, faces, start) * base.travel.start_m);
    g.basis = image == start ? "measured" : "symmetry";
    g.heading_deg = sim::wrap_deg(deg(std::atan2(d.y(), d.x())));
    g.speed_m_per_min = (r.feasible ? d.norm() : 0.0) * 60.0 / args.duration_s;
    if (image == start) record_gait(g.policy, r);
    set.gaits.push_back(std::move(g));
  }
  sim::save_gait_set(args.out, set);
  std::printf("wrote %s: %zu gaits from %s\n", args.out.c_str(), set.gaits.size(), args.policy.c_str());
  for (const sim::Gait& g : set.gaits) {
    std::printf("  %-12s face %d-%d-%d  heading %+7.1f deg  %5.1f m/min  (%s)\n", g.name.c_str(), g.face[0], g.face[1],
                g.face[2], g.heading_deg, g.speed_m_per_min, g.basis.c_str());
  }
}

void add_common(CLI::App* cmd, GaitsArgs& args, bool policy_required) {
  cmd->add_option("--robot", args.robot,
                  "Robot description (default: the one the policy names, else robots/superball-paper.json)")
      ->check(CLI::ExistingFile);
  auto* policy =
      cmd->add_option("--policy", args.policy, "Policy file (tensegrity-policy/1)")->check(CLI::ExistingFile);
  if (policy_required) policy->required();
}

}  // namespace

void add_gaits_command(CLI::App& app) {
  auto args = std::make_shared<GaitsArgs>();
  CLI::App* gaits = app.add_subcommand("gaits", "The robot's symmetries and the gaits they make of a policy");
  gaits->require_subcommand(1);

  CLI::App* sym = gaits->add_subcommand("symmetries", "List the robot's symmetries and what each does to a gait");
  add_common(sym, *args, false);
  sym->add_flag("--json", args->json, "Print one JSON object");
  sym->callback([args] { run_symmetries(*args); });

  CLI::App* tr = gaits->add_subcommand("transform", "Write a policy's image under one of the robot's symmetries");
  add_common(tr, *args, true);
  tr->add_option("--symmetry", args->symmetry,
                 "The symmetry, by name as `gaits symmetries` lists it, e.g. \"(-x, y, z)\"")
      ->required();
  tr->add_option("--out", args->out, "Policy file to write")->required();
  tr->add_option("--duration", args->duration_s, "Episode that measures the image's heading, seconds")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 3600.0));
  tr->add_flag("!--no-measure", args->measure, "Do not play the image to record its heading");
  tr->callback([args] { run_transform(*args); });

  CLI::App* set = gaits->add_subcommand("set", "Write the gait set a policy and the robot's symmetries give");
  add_common(set, *args, true);
  set->add_option("--out", args->out, "Gait set file to write (tensegrity-gait-set/1)")->required();
  set->add_option("--duration", args->duration_s, "Episode that measures heading and speed, seconds")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 3600.0));
  set->callback([args] { run_set(*args); });
}

}  // namespace tensegrity::cli
