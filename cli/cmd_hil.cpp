// SPDX-License-Identifier: Apache-2.0
// `tensegrity hil`: the HIL emulator with twelve `endcap` programs (lockstep or
// real time, optional fault scenario and per-tick record). `bench hil` is in
// cmd_bench_hil.cpp.
#include <sys/resource.h>

#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/shipped_policy.hpp"
#include "cli/stop_signals.hpp"
#ifdef TENSEGRITY_CLI_DDS
#include "cli/ground_cli.hpp"
#include "ground/keystore.hpp"
#include "msgs/security.hpp"
#endif
#ifdef TENSEGRITY_CLI_VIEW
#include "cli/view_options.hpp"
#include "hil/dds_domain.hpp"
#endif
#include "hil/hil_error.hpp"
#include "hil/hil_run.hpp"
#include "sim/model/core_controller.hpp"
#include "sim/model/episode.hpp"
#include "robot/policy.hpp"
#ifdef TENSEGRITY_CLI_VIEW
#include "view/modes.hpp"
#endif

namespace tensegrity::cli {
namespace {

namespace fs = std::filesystem;

struct HilArgs {
  std::string robot;
  std::string policy;
  double duration_s = 60.0;
  std::string mode = "lockstep";
  std::string scenario;
  std::vector<std::string> faults;
  std::string record;
  std::string endcap;
  double barrier_timeout_s = 2.0;
  double speed = -1.0;  // not given: 1 for a lockstep run with --view, else no limit
  std::string provision = hil::to_string(hil::default_provision());
  std::string host_loss = "stop";
  int domain = -1;
  std::string keystore;
  int link_attempts = 3;
  bool insecure = false;
  bool secure = false;
  std::vector<int> disabled_cables;
  std::string cable_failure = "drive";
  bool keep = false;
  bool json = false;
  bool view = false;
#ifdef TENSEGRITY_CLI_VIEW
  double view_wait_s = 60.0;
  ViewServerArgs view_server;
#endif
};

hil::HilOptions make_options(const HilArgs& a) {
  hil::HilOptions o;
  o.robot = a.robot;
  o.policy = shipped_policy_or(a.policy);
  o.duration_s = a.duration_s;
  o.mode = a.mode == "realtime" ? hil::StepperMode::realtime : hil::StepperMode::lockstep;
  o.record_csv = a.record;
  o.endcap_binary = a.endcap;
  o.barrier_timeout_s = a.barrier_timeout_s;
  if (a.speed >= 0.0 && o.mode != hil::StepperMode::lockstep) {
    throw CommandError(ExitCode::usage, "hil: --speed is for lockstep runs (a realtime run keeps to the wall clock)");
  }
  // A factor near 0 would sleep for days between ticks, deaf to Ctrl-C.
  if (a.speed > 0.0 && a.speed < 0.01)
    throw CommandError(ExitCode::usage, "hil: --speed must be 0 (no limit) or 0.01..1000");
  o.max_speed = a.speed >= 0.0 ? a.speed : (a.view && o.mode == hil::StepperMode::lockstep ? 1.0 : 0.0);
  o.keep_dir = a.keep;
  o.provision = a.provision == "local" ? hil::Provision::local : hil::Provision::dds;
  o.host_loss = a.host_loss;
  o.dds_domain = a.domain;
  o.link_attempts = a.link_attempts;
  // Secured unless --insecure, with --keystore DIR or the default keystore; the HIL
  // runs both ends, so it makes the keystore if there is none yet.
#ifdef TENSEGRITY_CLI_DDS
  if (a.secure && a.insecure) throw CommandError(ExitCode::usage, "hil: --secure and --insecure exclude each other");
  if (!a.insecure) o.dds_keystore = a.keystore.empty() ? msgs::default_keystore() : std::filesystem::path(a.keystore);
#endif
  const sim::Robot robot =
      sim::load_robot(a.robot.empty() ? sim::robot_path_for_policy(o.policy) : std::filesystem::path(a.robot));
  try {
    if (!a.scenario.empty()) o.scenario = hil::load_scenario(a.scenario, robot.endcap_count());
    for (const auto& f : a.faults) o.scenario.events.push_back(hil::parse_fault_option(f, robot.endcap_count()));
    for (int cable : a.disabled_cables) {
      const auto failure = a.cable_failure == "drive"   ? hil::CableFailure::drive
                           : a.cable_failure == "spool" ? hil::CableFailure::spool
                                                        : hil::CableFailure::seize;
      o.scenario.events.push_back(hil::disabled_cable_event(robot, cable, failure));
    }
    hil::sort_events(o.scenario);
    hil::check_scenario(o.scenario, robot);
  } catch (const hil::HilError& e) {
    throw CommandError(ExitCode::usage, e.what());
  }
  return o;
}

#ifdef TENSEGRITY_CLI_VIEW
// `--view`: the live page of this run, served while it runs. The view needs the
// run's DDS domain before the run leases it, so a free one is chosen here; another
// run taking it in between fails this one with a clear "domain in use".
std::unique_ptr<view::LiveView> open_view(const HilArgs& args, hil::HilOptions& o, const sim::Robot& robot) {
  if (!args.view) return nullptr;
  if (o.provision != hil::Provision::dds)
    throw CommandError(ExitCode::usage, "hil: --view needs --provision dds (the end caps' DDS link)");
  if (o.dds_domain < 0) o.dds_domain = hil::DomainLease(-1).domain();
  std::unique_ptr<view::LiveView> v;
  try {
    std::filesystem::path enclave;
    if (!o.dds_keystore.empty()) {
      ground::ensure_keystore(o.dds_keystore);
      enclave = msgs::enclave_dir(o.dds_keystore, msgs::enclave_name(msgs::Role::listener));
    }
    v = std::make_unique<view::LiveView>(robot, o.dds_domain, to_server_options(args.view_server), enclave);
  } catch (const std::exception& e) {
    throw CommandError(ExitCode::usage, std::string("hil --view: ") + e.what());
  }
  std::fprintf(stderr, "view: live page of this run (DDS domain %d) at %s\n", o.dds_domain, v->url().c_str());
  if (args.view_wait_s > 0) {
    std::fprintf(stderr, "view: the run starts when a page is open (at most %.0f s)\n", args.view_wait_s);
    if (!v->wait_for_page(args.view_wait_s)) std::fprintf(stderr, "view: no page yet, starting anyway\n");
  }
  return v;
}
#else
// A build without DDS has no live view, and `hil` offers no --view.
std::nullptr_t open_view(const HilArgs&, hil::HilOptions&, const sim::Robot&) { return nullptr; }
#endif

void run_hil_command(const HilArgs& args) {
  // Ctrl-C ends the run in order: the children are shut down, the temp dir removed.
  const StopOnSignals stop;
  hil::HilOptions options = make_options(args);
  options.stop = stop.token();
  // Before the run raises this thread's priority: the view's threads stay ordinary.
  [[maybe_unused]] const auto page =
      open_view(args, options,
                sim::load_robot(options.robot.empty() ? sim::robot_path_for_policy(options.policy) : options.robot));
  const hil::HilResult r = hil::run_hil(options);
  if (args.json) {
    std::printf("%s\n", hil::to_json(r).dump(2).c_str());
  } else {
    std::printf("%s", hil::summary_text(r).c_str());
  }
  if (!r.ok) throw CommandError(ExitCode::failure, "hil: " + r.error);
}

}  // namespace

void add_hil_command(CLI::App& app) {
  auto args = std::make_shared<HilArgs>();
  CLI::App* cmd = app.add_subcommand("hil", "Run the HIL emulator with 12 end-cap firmware processes");
  cmd->add_option("--robot", args->robot, "Robot description (default: the one the policy names)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--policy", args->policy, std::string("Policy file (default: ") + kShippedPolicy + ")")
      ->check(CLI::ExistingFile);
  cmd->add_option("--duration", args->duration_s, "Physics time, seconds")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 86400.0));
  cmd->add_option("--mode", args->mode, "lockstep (the emulator owns time) or realtime (1 kHz wall clock)")
      ->capture_default_str()
      ->check(CLI::IsMember({"lockstep", "realtime"}));
  cmd->add_option("--scenario", args->scenario, "Fault scenario (tensegrity-hil-scenario/1 JSON)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--fault", args->faults, "One fault, ENDCAP:FAULT@TIME_S (repeatable), e.g. 3:drive_fault@2.0");
  cmd->add_option("--record", args->record, "Run record CSV, one row per physics step (as sim --telemetry)");
  cmd->add_option("--endcap", args->endcap,
                  "The endcap program (default: the one built with this tree, or $TENSEGRITY_ENDCAP)");
  cmd->add_option("--barrier-timeout", args->barrier_timeout_s, "Lockstep: seconds to wait for an end cap's targets")
      ->capture_default_str()
      ->check(CLI::Range(0.01, 600.0));
  cmd->add_option("--speed", args->speed,
                  "Lockstep: physics at most this many times real time, 0 for as fast as the end caps answer "
                  "(default: 0; 1 with --view, so that the page shows the run as it would happen)")
      ->check(CLI::Range(0.0, 1000.0));
  cmd->add_option("--provision", args->provision,
                  "dds: upload and start over DDS as on the robot (`tensegrity upload`/`start`); "
                  "local: each end cap gets --policy FILE --start-on-boot, no DDS")
      ->capture_default_str()
      ->check(CLI::IsMember({"dds", "local"}));
  cmd->add_option("--host-loss", args->host_loss, "dds: what the end caps do when the host's link is lost")
      ->capture_default_str()
      ->check(CLI::IsMember({"continue", "stop"}));
  cmd->add_option("--domain", args->domain, "dds: DDS domain of this run (default: a free one of 215..232)")
      ->check(CLI::Range(0, 232));
  cmd->add_option("--link-attempts", args->link_attempts,
                  "dds: start the run afresh this many times at most when the link does not come up before the "
                  "start (Fast DDS's stalled secured handshakes; docs/guide/security.md)")
      ->check(CLI::Range(1, 10))
      ->capture_default_str();
#ifdef TENSEGRITY_CLI_DDS
  add_security_options(*cmd, args->keystore, args->insecure);
  cmd->add_flag("--secure", args->secure,
                "dds: DDS Security with the default keystore (the default; TENSEGRITY_KEYSTORE, else "
                "~/.local/share/tensegrity/keystore; made if missing)");
#endif
  cmd->add_option("--disable-cable", args->disabled_cables,
                  "Cable (muscle) M fails from the start (the paper's Figure 13); repeatable. How: --cable-failure")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--cable-failure", args->cable_failure,
                  "drive: the cable's drive faults (EMCY) and releases it (slack, at the longest rest length); its end "
                  "cap goes to its safe state, so its other cable holds. spool: only the spool runs free (slack); the "
                  "end cap does not notice and keeps playing its other cable. seize: only the spool seizes (the cable "
                  "keeps its start length); the end cap plays on")
      ->capture_default_str()
      ->check(CLI::IsMember({"drive", "spool", "seize"}));
  cmd->add_flag("--keep", args->keep, "Keep the run directory (configs, stores, logs)");
  cmd->add_flag("--json", args->json, "Print one JSON object");
#ifdef TENSEGRITY_CLI_VIEW
  cmd->add_flag("--view", args->view, "Serve the live page of this run (tensegrity view --live on its domain)");
  cmd->add_option("--view-wait", args->view_wait_s, "--view: seconds to wait for a page before starting (0: none)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 3600.0));
  cmd->add_option("--view-port", args->view_server.port, "--view: HTTP port of the page")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  cmd->add_option("--view-bind", args->view_server.bind, "--view: address to listen on")->capture_default_str();
#endif
  cmd->callback([args] { run_hil_command(*args); });
}

}  // namespace tensegrity::cli
