// SPDX-License-Identifier: Apache-2.0
// `tensegrity analyze POLICY --out DIR`: one episode in process, analysed as the
// paper's Figures 10-12 and the rolling evidence; CSV files, a JSON summary, and PNGs
// from tools/plot_analysis.py when python3 with matplotlib is there.
#include <spawn.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "cli/episode_cli.hpp"
#include "sim/analysis/analysis_json.hpp"
#include "sim/analysis/csv_files.hpp"
#include "sim/model/core_controller.hpp"
#include "robot/policy.hpp"

extern char** environ;

namespace tensegrity::cli {
namespace {

struct AnalyzeArgs {
  std::string policy;
  std::string robot;
  std::string out;
  double duration_s = 60.0;
  double sample_hz = 100.0;
  double contact_tolerance_m = 0.002;
  double cluster_cut = 0.5;
  bool plots = true;
  bool json = false;
};

std::filesystem::path plot_script() {
  const std::filesystem::path rel = "tools/plot_analysis.py";
  if (const char* dir = std::getenv("TENSEGRITY_SOURCE_DIR")) return std::filesystem::path(dir) / rel;
#ifdef TENSEGRITY_SOURCE_DIR
  if (std::filesystem::exists(std::filesystem::path(TENSEGRITY_SOURCE_DIR) / rel)) {
    return std::filesystem::path(TENSEGRITY_SOURCE_DIR) / rel;
  }
#endif
  return rel;
}

// Debian's python3 carries matplotlib (scripts/debian-packages.txt); a virtualenv
// first on PATH often does not. TENSEGRITY_PYTHON overrides both.
std::string python() {
  if (const char* p = std::getenv("TENSEGRITY_PYTHON")) return p;
  return std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
}

// The readable form of the summary (sim/analysis/analysis_json.hpp).
void print_analysis_summary(const nlohmann::json& j) {
  const auto& m = j["rest_length_m"];
  const auto& p = j["power_per_muscle_w"];
  const auto& r = j["rolling"];
  const auto& period = j["revolution_period_s"];
  std::printf("  window           %.1f-%.1f s (%zu samples)\n", j["window_s"][0].get<double>(),
              j["window_s"][1].get<double>(), j["samples"].get<std::size_t>());
  std::printf("  rest lengths     %.3f-%.3f m, means %.3f-%.3f m\n", m["min"].get<double>(), m["max"].get<double>(),
              m["mean_lowest"].get<double>(), m["mean_highest"].get<double>());
  std::printf("  tension          mean %.1f N, peak %.1f N\n", j["tension_n"]["mean"].get<double>(),
              j["tension_n"]["peak"].get<double>());
  std::printf("  power per muscle mean %.2f W (muscles %.2f-%.2f W; 1 s mean %.2f-%.2f W)\n", p["mean"].get<double>(),
              p["lowest_muscle"].get<double>(), p["highest_muscle"].get<double>(), p["mean_over_1s_min"].get<double>(),
              p["mean_over_1s_max"].get<double>());
  const auto& from = r["face_cycle_from_s"];
  std::printf(
      "  revolution       %.2f s from contacts, %.2f s from faces (%d per cycle, from %.1f s), %.2f s from "
      "rotation\n",
      period["contacts"].get<double>(), period["faces"].get<double>(), r["faces_per_cycle"].get<int>(),
      from.is_null() ? 0.0 : from.get<double>(), period["rotation"].get<double>());
  std::printf("  rolling          %.2f revolutions, %d of %d end caps touched, %zu faces, slip median %.3f m/s\n",
              r["revolutions"].get<double>(), r["endcaps_touched_count"].get<int>(), j["endcaps"].get<int>(),
              r["face_sequence"].size(), r["slip_m_per_s"]["median"].get<double>());
  std::printf("  clusters         %zu (zero lag), %zu (phase aligned) at 1 - r <= %.2f\n",
              j["clusters"]["zero_lag"].size(), j["clusters"]["phase_aligned"].size(),
              j["clusters"]["cut_height"].get<double>());
}

// Runs the plotting script; returns what happened, for the summary.
std::string make_plots(const std::filesystem::path& dir) {
  const std::string py = python(), script = plot_script().string(), out = dir.string();
  if (!std::filesystem::exists(script)) return "skipped: " + script + " not found";
  std::vector<char*> argv{const_cast<char*>(py.c_str()), const_cast<char*>(script.c_str()),
                          const_cast<char*>(out.c_str()), nullptr};
  pid_t pid = 0;
  if (posix_spawnp(&pid, py.c_str(), nullptr, nullptr, argv.data(), environ) != 0) {
    return "skipped: cannot run " + py;
  }
  int status = 0;
  waitpid(pid, &status, 0);
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return "written";
  // tools/plot_analysis.py's own status when it cannot import matplotlib.
  constexpr int kNoMatplotlib = 3;
  if (WIFEXITED(status) && WEXITSTATUS(status) == kNoMatplotlib)
    return "skipped: matplotlib is not installed for " + py;
  if (WIFEXITED(status) && WEXITSTATUS(status) == exit_status(ExitCode::cannot_exec)) {
    return "skipped: " + py + " not found";
  }
  return "failed: " + py + " " + script + " exited with status " + std::to_string(status);
}

void run_analyze(const AnalyzeArgs& args) {
  const sim::Robot robot = load_robot_arg(args.robot, args.policy);
  const sim::Policy policy = sim::load_policy(args.policy, robot);
  sim::CoreController controller(robot, policy);
  sim::analysis::EpisodeSeries series;
  sim::analysis::SeriesRecorder recorder(series);
  sim::EpisodeOptions options;
  options.duration_s = args.duration_s;
  options.telemetry = &recorder;
  options.telemetry_every = std::max(1, static_cast<int>(std::lround(1.0 / (args.sample_hz * robot.time_step_s))));
  std::fprintf(stderr, "analyze: %s on %s, %.0f s episode at %.0f Hz...\n", args.policy.c_str(), robot.name.c_str(),
               args.duration_s, 1.0 / (options.telemetry_every * robot.time_step_s));
  const sim::EpisodeResult result = sim::run_episode(robot, controller, options);
  if (series.samples() < 4)
    throw CommandError(ExitCode::failure, "analyze: the episode ended before 4 samples were recorded");

  sim::analysis::AnalysisOptions analysis_options;
  analysis_options.period_s = policy.period_s;
  analysis_options.contacts.tolerance_m = args.contact_tolerance_m;
  analysis_options.cluster_cut = args.cluster_cut;
  std::vector<std::pair<int, int>> cable_nodes;
  for (const auto& c : robot.cables) cable_nodes.emplace_back(c.node_a, c.node_b);
  const auto analysis = sim::analysis::analyze(series, cable_nodes, analysis_options);

  const std::filesystem::path dir = args.out;
  nlohmann::json summary = sim::analysis::analysis_json(series, analysis, analysis_options);
  summary["policy"] = args.policy;
  summary["robot"] = robot.name;
  summary["robot_hash"] = robot.hash;
  summary["period_s"] = policy.period_s;
  summary["episode"] = episode_json(result);
  summary["files"] = sim::analysis::write_csv_files(dir, series, analysis);
  // The plotting script reads the summary too; it is rewritten with the plots' status.
  std::ofstream(dir / "summary.json") << summary.dump(2) << '\n';
  std::fprintf(stderr, "analyze: CSV files in %s; plotting...\n", dir.string().c_str());
  summary["plots"] = args.plots ? make_plots(dir) : std::string("skipped: --no-plots");
  std::ofstream(dir / "summary.json") << summary.dump(2) << '\n';
  if (args.json) {
    std::printf("%s\n", summary.dump(2).c_str());
    return;
  }
  std::printf("%s on %s (%s), %.1f s\n", args.policy.c_str(), robot.name.c_str(), robot.hash.c_str(), args.duration_s);
  print_episode_summary(result);
  print_analysis_summary(summary);
  std::printf("  files            %s (summary.json, %zu CSV; plots %s)\n", dir.string().c_str(),
              summary["files"].size(), summary["plots"].get<std::string>().c_str());
}

}  // namespace

void add_analyze_command(CLI::App& app) {
  auto args = std::make_shared<AnalyzeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "analyze",
      "Play a policy for one episode and write Figures 10-12 (rest lengths, tensions, energy, power, "
      "correlation and clustering of the signals) and the rolling evidence as CSV and PNG");
  cmd->add_option("POLICY", args->policy, "Policy file to play (tensegrity-policy/1)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--robot", args->robot, "Robot description (default: the one the policy names)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--duration", args->duration_s, "Episode length, seconds")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 3600.0));
  cmd->add_option("--out", args->out, "Directory for the CSV files, PNGs and summary.json")->required();
  cmd->add_option("--sample-rate", args->sample_hz, "Samples per second kept for the analysis")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 1000.0));
  cmd->add_option("--contact-tolerance", args->contact_tolerance_m,
                  "An end cap touches the ground when its surface is within this, metres")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.05));
  cmd->add_option("--cluster-cut", args->cluster_cut,
                  "Flat clusters: cut the average-linkage tree on 1 - r at this height")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 2.0));
  cmd->add_flag("!--no-plots", args->plots, "Write the CSV files only");
  cmd->add_flag("--json", args->json, "Print the summary as one JSON object (also written to DIR/summary.json)");
  cmd->callback([args] { run_analyze(*args); });
}

}  // namespace tensegrity::cli
