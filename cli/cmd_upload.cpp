// SPDX-License-Identifier: Apache-2.0
// `tensegrity upload POLICY.json`: each end cap gets its share of the policy,
// validated and acknowledged by the end cap; prints one row per end cap and exits
// non-zero unless every end cap accepted.
#include <chrono>
#include <cstdio>
#include <ctime>

#include "cli/commands.hpp"
#include "cli/ground_cli.hpp"
#include "ground/upload.hpp"

namespace tensegrity::cli {

void add_upload_command(CLI::App& app) {
  struct Args {
    std::string policy;
    std::string robot;
    std::string id;
    std::int64_t version = -1;
    bool force = false;
    GroundOptions ground;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("upload", "Send a policy to the end caps and wait for every acknowledgement");
  cmd->add_option("policy", args->policy, "Policy file (tensegrity-policy/1)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--robot", args->robot, "Robot file (default: the one the policy names)")->check(CLI::ExistingFile);
  cmd->add_option("--id", args->id, "Policy id (default: the file name without extension; at most 64 chars)");
  cmd->add_option("--policy-version", args->version,
                  "Policy version; must exceed the active one (default: Unix time in seconds)")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{0xFFFFFFFF}));
  cmd->add_flag("--force", args->force, "Accept a version not newer than the active one");
  add_ground_options(*cmd, args->ground, 10.0);
  cmd->callback([args] {
    const sim::Robot robot = sim::load_robot(args->robot.empty() ? sim::robot_path_for_policy(args->policy)
                                                                 : std::filesystem::path(args->robot));
    const sim::Policy policy = sim::load_policy(args->policy, robot);
    fw::comms::PolicyIdentity identity;
    identity.policy_id = args->id.empty() ? std::filesystem::path(args->policy).stem().string() : args->id;
    if (identity.policy_id.empty() || identity.policy_id.size() > 64) {
      throw CommandError(ExitCode::usage, "policy id '" + identity.policy_id + "' must be 1..64 characters (--id)");
    }
    identity.policy_version =
        args->version > 0 ? static_cast<std::uint32_t>(args->version) : static_cast<std::uint32_t>(std::time(nullptr));
    identity.robot = robot.name;
    identity.force = args->force;
    std::vector<ground::msg::PolicyTable_> tables =
        ground::policy_messages(policy, robot, identity, ground::random_sequence_base());
    const std::uint16_t mask = parse_endcap_set(args->ground.endcaps);
    std::erase_if(tables, [mask](const auto& t) { return (mask & (1U << t.target_endcap())) == 0; });

    auto station = make_station(args->ground);
    // Let discovery finish first (heartbeats seen), so the first send usually
    // reaches everyone; the upload re-sends to whoever is still missing anyway.
    wait_for_endcaps(*station, args->ground, false);
    ground::UploadOptions options;
    options.timeout_s = args->ground.timeout_s;
    std::printf("uploading %s v%u (robot %s) to %zu end caps\n", identity.policy_id.c_str(), identity.policy_version,
                robot.name.c_str(), tables.size());
    const ground::UploadReport report = ground::upload(*station, tables, options);
    std::printf("%s", ground::format_upload_report(report).c_str());
    if (!report.all_accepted())
      throw CommandError(ExitCode::failure, "upload incomplete: not every end cap accepted the policy");
    std::printf("all %zu end caps accepted in %.1f ms\n", report.results.size(), report.total_s * 1e3);
  });
}

}  // namespace tensegrity::cli
