// SPDX-License-Identifier: Apache-2.0
// `tensegrity soak`: the HIL's chaos soak (hil/soak_run.hpp): a real-time run with a
// seeded random scenario of kills, restarts, link cuts, drive reboots and an
// operator's estops, clears and starts, its invariants checked throughout. Exit 1,
// naming the violations, when one broke.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>

#include "cli/commands.hpp"
#include "cli/ground_cli.hpp"
#include "cli/shipped_policy.hpp"
#include "cli/stop_signals.hpp"
#include "hil/hil_error.hpp"
#include "hil/soak_run.hpp"
#include "msgs/security.hpp"
#include "robot/policy.hpp"

namespace tensegrity::cli {
namespace {

struct SoakArgs {
  std::string robot;
  std::string policy;
  double duration_s = 120.0;
  std::uint64_t seed = 1;
  int domain = -1;
  std::string keystore;
  bool insecure = false;
  double estop_bound_ms = 500.0;
  double settle_s = 15.0;
  double mean_gap_s = 5.0;
  std::string endcap;
  std::string plan;
  std::string out;
  bool json = false;
};

hil::SoakOptions make_options(const SoakArgs& a) {
  hil::SoakOptions o;
  o.robot = a.robot;
  o.policy = shipped_policy_or(a.policy);
  o.duration_s = a.duration_s;
  o.seed = a.seed;
  o.dds_domain = a.domain;
  // The soak runs both ends, so it makes the keystore if there is none yet (as `hil`).
  if (!a.insecure) o.dds_keystore = a.keystore.empty() ? msgs::default_keystore() : std::filesystem::path(a.keystore);
  o.estop_bound_s = a.estop_bound_ms * 1e-3;
  o.settle_s = a.settle_s;
  o.mean_gap_s = a.mean_gap_s;
  o.endcap_binary = a.endcap;
  return o;
}

void write_file(const std::string& path, const nlohmann::json& j) {
  std::ofstream f(path);
  if (!(f << j.dump(2) << "\n")) throw CommandError(ExitCode::usage, "soak: cannot write " + path);
}

void run_soak_command(const SoakArgs& args) {
  const StopOnSignals stop;
  hil::SoakOptions options = make_options(args);
  options.stop = stop.token();
  if (!args.plan.empty()) {
    try {
      const sim::Robot robot =
          sim::load_robot(options.robot.empty() ? sim::robot_path_for_policy(options.policy) : options.robot);
      write_file(args.plan, hil::scenario_json(hil::soak_scenario(options, robot)));
    } catch (const hil::HilError& e) {
      throw CommandError(ExitCode::usage, e.what());
    }
    return;
  }
  hil::SoakResult r;
  try {
    r = hil::run_soak(options);
  } catch (const hil::HilError& e) {
    throw CommandError(ExitCode::usage, e.what());
  }
  if (!args.out.empty()) write_file(args.out, hil::to_json(r));
  if (args.json) {
    std::printf("%s\n", hil::to_json(r).dump(2).c_str());
  } else {
    std::printf("%s", hil::summary_text(r).c_str());
  }
  if (!r.ok) {
    std::string names;
    for (const auto& v : r.violations) names += "\n  " + v.describe();
    const std::string message = "soak: " + std::to_string(r.violations.size()) + " invariant violation(s):" + names;
    if (r.operator_hung) {
      // A thread stuck in Fast DDS: leave without the static destructors that would join it.
      std::fprintf(stderr, "tensegrity: %s\n", message.c_str());
      std::fflush(nullptr);
      std::_Exit(exit_status(ExitCode::failure));
    }
    throw CommandError(ExitCode::failure, message);
  }
}

}  // namespace

void add_soak_command(CLI::App& app) {
  auto args = std::make_shared<SoakArgs>();
  CLI::App* cmd = app.add_subcommand(
      "soak",
      "Chaos soak: a real-time HIL run with random (seeded) end-cap kills and restarts, link cuts, drive reboots, "
      "estops, clears and starts, checking its invariants throughout (tension, estop reach, tables, host loss, "
      "memory)");
  cmd->add_option("--duration", args->duration_s, "Real time, seconds")
      ->capture_default_str()
      ->check(CLI::Range(30.0, 86400.0));
  cmd->add_option("--seed", args->seed, "Seed of the random scenario (the same seed, the same scenario)")
      ->capture_default_str();
  cmd->add_option("--robot", args->robot, "Robot description (default: the one the policy names)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--policy", args->policy, std::string("Policy file (default: ") + kShippedPolicy + ")")
      ->check(CLI::ExistingFile);
  cmd->add_option("--domain", args->domain, "DDS domain of this run (default: a free one of 215..232)")
      ->check(CLI::Range(0, 232));
  add_security_options(*cmd, args->keystore, args->insecure);
  cmd->add_option("--estop-bound-ms", args->estop_bound_ms,
                  "Every running end cap on the link acks each estop within this many milliseconds")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 10000.0));
  cmd->add_option("--settle", args->settle_s,
                  "Seconds after an end cap's restart or its link's restore before an estop must reach it")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 600.0));
  cmd->add_option("--mean-gap", args->mean_gap_s, "Mean seconds between the scenario's episodes")
      ->capture_default_str()
      ->check(CLI::Range(0.5, 600.0));
  cmd->add_option("--endcap", args->endcap,
                  "The endcap program (default: the one built with this tree, or $TENSEGRITY_ENDCAP)");
  cmd->add_option("--plan", args->plan,
                  "Write the scenario (tensegrity-hil-scenario/1, for `tensegrity hil --scenario`) to FILE and stop");
  cmd->add_option("--out", args->out, "Also write the JSON result to FILE");
  cmd->add_flag("--json", args->json, "Print one JSON object (format tensegrity-soak/1)");
  cmd->callback([args] { run_soak_command(*args); });
}

}  // namespace tensegrity::cli
