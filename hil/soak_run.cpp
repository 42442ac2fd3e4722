// SPDX-License-Identifier: Apache-2.0
#include "hil/soak_run.hpp"

#include <atomic>
#include <cstdlib>
#include <mutex>
#include <sstream>

#include "ground/keystore.hpp"
#include "hil/dds_domain.hpp"
#include "hil/process_launcher.hpp"
#include "hil/soak_memory.hpp"
#include "hil/soak_operator.hpp"
#include "msgs/security.hpp"
#include "robot/policy.hpp"

namespace tensegrity::hil {

namespace {

double load_average_1min() {
  double load[1] = {0.0};
  return ::getloadavg(load, 1) == 1 ? load[0] : -1.0;
}

sim::Robot robot_of(const SoakOptions& o) {
  return sim::load_robot(o.robot.empty() ? sim::robot_path_for_policy(o.policy) : o.robot);
}

// The operator ends this long before the run's end, while the end caps still run.
constexpr double kOperatorEndS = 1.0;

// What the stepper's thread records each step: nothing that can block.
struct StepWatch {
  std::atomic<double> max_tension_n{0.0};
  std::atomic<double> first_over_s{-1.0};
};

HilOptions hil_options(const SoakOptions& o, const Scenario& scenario, int domain) {
  HilOptions h;
  h.robot = o.robot;
  h.policy = o.policy;
  h.duration_s = o.duration_s;
  h.mode = StepperMode::realtime;
  h.scenario = scenario;
  h.provision = Provision::dds;
  h.host_loss = "stop";
  h.dds_domain = domain;
  h.dds_keystore = o.dds_keystore;
  h.endcap_binary = o.endcap_binary;
  h.boot_timeout_s = 60.0;  // twelve secured participants on a loaded 2-core host
  h.stop = o.stop;
  return h;
}

}  // namespace

Scenario soak_scenario(const SoakOptions& options, const sim::Robot& robot) {
  SoakPlanOptions p;
  p.seed = options.seed;
  p.duration_s = options.duration_s;
  p.mean_gap_s = options.mean_gap_s;
  p.settle_s = options.settle_s;
  for (int e = 0; e < robot.endcap_count(); ++e) p.motors.push_back(static_cast<int>(robot.cables_of(e).size()));
  return make_soak_scenario(p);
}

SoakResult run_soak(const SoakOptions& options) {
  const sim::Robot robot = robot_of(options);
  SoakResult result;
  result.seed = options.seed;
  result.duration_s = options.duration_s;
  result.scenario = soak_scenario(options, robot);
  result.load_average_start = load_average_1min();
  const int n = robot.endcap_count();
  const SoakTimeline timeline(result.scenario, n, options.settle_s);
  SoakBounds bounds;
  bounds.tension_limit_n = robot.motor.hard_limit_tension_n;
  bounds.estop_s = options.estop_bound_s;
  SoakChecker checker(timeline, n, bounds);
  std::mutex checked;  // the operator's thread feeds the checker; the end reads it
  // The operator needs the run's domain before the run leases it (as `hil --view`).
  const int domain = options.dds_domain >= 0 ? options.dds_domain : DomainLease(-1).domain();
  std::filesystem::path enclave;
  if (!options.dds_keystore.empty()) {
    ground::ensure_keystore(options.dds_keystore);
    enclave = msgs::enclave_dir(options.dds_keystore, msgs::enclave_name(msgs::Role::ground));
  }
  SoakOperatorSinks sinks;
  sinks.estop = [&](double t_s, const std::vector<SoakAck>& acks) {
    const std::lock_guard lock(checked);
    checker.estop(t_s, acks);
  };
  sinks.table = [&](double t_s, int e, std::uint32_t life, const std::string& id, std::uint32_t v, double heard_s) {
    const std::lock_guard lock(checked);
    checker.table(t_s, e, life, id, v, heard_s);
  };
  sinks.log = [&](const std::string& line) {
    const std::lock_guard lock(checked);
    result.operator_log.push_back(line);
  };
  RssSampler memory;
  StepWatch watch;
  // On the heap: if its station's deletion hangs, it must outlive the process.
  auto* op_owner = new SoakOperator(domain, enclave, n, sinks);
  {
    SoakOperator& op = *op_owner;
    HilOptions h = hil_options(options, result.scenario, domain);
    h.operator_command = [&op](const ScenarioEvent& ev) { return op.post(ev); };
    const double limit_n = bounds.tension_limit_n;
    h.after_step = [&](const WorldStepper& s, ProcessLauncher& launcher) {
      const double t_s = s.stats().sim_time_s();
      op.set_time(t_s);
      if (t_s >= options.duration_s - kOperatorEndS) op.finish();  // before the end caps shut down
      const double max_n = s.stats().max_tension_n;
      watch.max_tension_n.store(max_n, std::memory_order_relaxed);
      if (max_n > limit_n && watch.first_over_s.load() < 0.0) watch.first_over_s.store(t_s);
      if (s.step_index() % 100 == 0) {
        memory.begin();
        for (int e = 0; e < n; ++e) memory.set_pid(e, launcher.started(e) ? launcher.pid(e) : 0);
      }
    };
    result.hil = run_hil(h);
  }
  result.operator_hung = !op_owner->stop();
  if (!result.operator_hung) delete op_owner;
  const std::lock_guard lock(checked);
  const double over_s = watch.first_over_s.load();
  checker.tension(over_s >= 0.0 ? over_s : options.duration_s, watch.max_tension_n.load());
  for (const EndcapSummary& e : result.hil.endcaps) checker.host_losses(e.endcap, e.host_losses);
  for (const auto& [process, samples] : memory.stop()) checker.memory(process, samples);
  if (!result.hil.ok) checker.run_failed(result.hil.error);
  if (result.operator_hung) checker.run_failed("the operator's station did not shut down within 10 s (Fast DDS)");
  result.violations = checker.violations();
  result.checks = checker.to_json();
  result.ok = result.hil.ok && result.violations.empty();
  result.load_average_end = load_average_1min();
  return result;
}

nlohmann::json to_json(const SoakResult& r) {
  nlohmann::json j{{"format", "tensegrity-soak/1"},
                   {"ok", r.ok},
                   {"seed", r.seed},
                   {"duration_s", r.duration_s},
                   {"load_average_start", r.load_average_start},
                   {"load_average_end", r.load_average_end},
                   {"events", r.scenario.events.size()},
                   {"scenario", scenario_json(r.scenario)},
                   {"operator_log", r.operator_log},
                   {"hil", to_json(r.hil)}};
  j.update(r.checks);
  return j;
}

std::string summary_text(const SoakResult& r) {
  std::ostringstream s;
  const nlohmann::json& inv = r.checks.at("invariants");
  s << "soak: seed " << r.seed << ", " << r.duration_s << " s real time, " << r.scenario.events.size()
    << " scenario events; load average " << r.load_average_start << " -> " << r.load_average_end << "\n";
  s << "  run: " << (r.hil.ok ? "completed" : "FAILED: " + r.hil.error) << ", " << r.hil.stats.late_steps << " of "
    << r.hil.stats.steps << " steps late\n";
  s << "  tension: max " << inv["tension"]["max_n"].get<double>() << " N (hard limit "
    << inv["tension"]["limit_n"].get<double>() << " N)\n";
  const auto& es = inv["estop"];
  s << "  estop: " << es["sent"] << " sent, " << es["acks_required"] << " acks required, latency p50 "
    << es["latency_p50_s"].get<double>() * 1e3 << " ms, p99 " << es["latency_p99_s"].get<double>() * 1e3 << " ms, max "
    << es["latency_max_s"].get<double>() * 1e3 << " ms (bound " << es["bound_s"].get<double>() * 1e3 << " ms)\n";
  s << "  table: " << inv["table"]["heartbeats"] << " heartbeats, all " << inv["table"]["policy_id"].get<std::string>()
    << " v" << inv["table"]["policy_version"] << " unless said below\n";
  s << "  host loss: " << inv["host_loss"]["losses"] << " losses, " << inv["host_loss"]["cuts"] << " cuts\n";
  int judged = 0;
  for (const auto& p : inv["memory"]["processes"]) judged += p["judged"].get<bool>() ? 1 : 0;
  s << "  memory: " << judged << " of " << inv["memory"]["processes"].size()
    << " processes lived long enough to judge\n";
  if (r.violations.empty()) {
    s << "soak: 0 violations\n";
  } else {
    s << "soak: " << r.violations.size() << " VIOLATION(S)\n";
    for (const SoakViolation& v : r.violations) s << "  " << v.describe() << "\n";
  }
  return s.str();
}

}  // namespace tensegrity::hil
