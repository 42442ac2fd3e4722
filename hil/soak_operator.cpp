// SPDX-License-Identifier: Apache-2.0
#include "hil/soak_operator.hpp"

#include <chrono>
#include <exception>
#include <memory>
#include <optional>

#include "ground/command.hpp"
#include "ground/station.hpp"
#include "ground/station_keeper.hpp"

namespace tensegrity::hil {

namespace {

constexpr double kCommandTimeoutS = 3.0;
// A start placed this far ahead in host time: every end cap hears it before it is due.
constexpr std::int64_t kStartLeadNs = 1'500'000'000;
constexpr auto kObservePeriod = std::chrono::milliseconds(100);  // heartbeats: 5 Hz

ground::CommandKind command_of(FaultKind fault) {
  switch (fault) {
    case FaultKind::estop: return ground::CommandKind::emergency_stop;
    case FaultKind::clear_fault: return ground::CommandKind::clear_fault;
    default: return ground::CommandKind::start;
  }
}

}  // namespace

SoakOperator::SoakOperator(int domain, const std::filesystem::path& enclave_dir, int endcap_count,
                           SoakOperatorSinks sinks)
    : endcap_count_(endcap_count), sinks_(std::move(sinks)) {
  thread_ = std::thread([this, enclave_dir, domain] {
    run(enclave_dir, domain);
    const std::lock_guard lock(done_mutex_);
    done_ = true;
    done_cv_.notify_all();
  });
}

SoakOperator::~SoakOperator() { static_cast<void>(stop()); }

bool SoakOperator::stop(double timeout_s) {
  finish();
  if (!thread_.joinable()) return true;
  std::unique_lock lock(done_mutex_);
  if (!done_cv_.wait_for(lock, std::chrono::duration<double>(timeout_s), [this] { return done_; })) {
    thread_.detach();
    return false;
  }
  lock.unlock();
  thread_.join();
  return true;
}

std::string SoakOperator::post(const ScenarioEvent& event) {
  if (!is_operator_command(event.fault)) return "not an operator's command";
  {
    const std::lock_guard lock(mutex_);
    queue_.push_back(event);
  }
  if (event.fault == FaultKind::estop) estop_queued_ = true;  // preempts a clear or start in flight
  wake_.notify_all();
  return "";
}

void SoakOperator::run(const std::filesystem::path& enclave_dir, int domain) {
  ground::StationOptions so;
  so.domain = domain;
  so.name = "soak-operator";
  so.publish_heartbeat = false;  // a bystander, as a console: not the end caps' host
  so.serve_time = false;
  so.enclave_dir = enclave_dir;
  std::unique_ptr<ground::StationKeeper> keeper;
  try {
    // As the console keeps its station: a handshake stalled with one end cap (heard,
    // not reached) is healed by a fresh participant beside the first.
    keeper = std::make_unique<ground::StationKeeper>([so] { return std::make_unique<ground::Station>(so); },
                                                     ground::StationKeeper::Options{});
  } catch (const std::exception& e) {
    if (sinks_.log) sinks_.log(std::string("operator: no station: ") + e.what());
    return;
  }
  while (!stop_) {
    std::optional<ScenarioEvent> next;
    {
      std::unique_lock lock(mutex_);
      wake_.wait_for(lock, kObservePeriod, [this] { return stop_ || !queue_.empty(); });
      if (!queue_.empty()) {
        next = queue_.front();
        queue_.pop_front();
      }
    }
    keeper->tick(ground::Station::now_ns());
    const std::shared_ptr<ground::Station> station = keeper->current();
    if (next) execute(*station, *next);
    observe(*station);
  }
  if (sinks_.log) sinks_.log("operator: the station joined again " + std::to_string(keeper->rejoins()) + " time(s)");
  keeper.reset();  // the stations deleted here, on this thread (stop() may stop waiting)
}

void SoakOperator::execute(ground::Station& station, const ScenarioEvent& ev) {
  const ground::CommandKind kind = command_of(ev.fault);
  ground::CommandOptions co;
  co.endcap_mask = ev.endcap < 0 ? ground::kAllEndcaps : static_cast<std::uint16_t>(1U << ev.endcap);
  co.timeout_s = kCommandTimeoutS;
  if (kind == ground::CommandKind::emergency_stop) {
    estop_queued_ = false;
    co.retry_interval_s = ground::kEstopRetryIntervalS;
  } else {
    co.keep_going = [this] { return !estop_queued_ && !stop_; };
  }
  const std::int64_t start_ns = kind == ground::CommandKind::start ? ground::Station::now_ns() + kStartLeadNs : 0;
  const auto before = station.snapshot();
  const ground::CommandReport report = ground::send_command(station, kind, start_ns, co);
  const auto after = station.snapshot();
  int accepted = 0;
  std::vector<SoakAck> acks(static_cast<std::size_t>(endcap_count_));
  std::map<std::string, std::string> refused;  // reason -> end caps
  for (const auto& r : report.results) {
    accepted += r.accepted ? 1 : 0;
    if (!r.accepted) refused[r.text] += (refused[r.text].empty() ? "" : ",") + std::to_string(r.endcap);
    if (r.endcap < 0 || r.endcap >= endcap_count_) continue;
    const auto e = static_cast<std::size_t>(r.endcap);
    const auto& was = before[e].heartbeat;
    const auto& is = after[e].heartbeat;
    const bool taken = before[e].seen && is.life_id() == was.life_id() && is.estops_received() > was.estops_received();
    acks[e] = {r.acked, r.latency_s, taken, after[e].seen};
  }
  if (kind == ground::CommandKind::emergency_stop && sinks_.estop) sinks_.estop(ev.time_s, acks);
  std::string why;
  for (const auto& [text, endcaps] : refused) why += "; " + endcaps + ": " + text;
  if (sinks_.log) {
    sinks_.log("operator: " + ev.describe() + ": " + std::to_string(accepted) + " of " +
               std::to_string(report.results.size()) + " accepted" +
               (report.preempted ? " (preempted by an estop)" : "") + why);
  }
}

void SoakOperator::observe(ground::Station& station) {
  if (!sinks_.table) return;
  const double t_s = now_s_.load(std::memory_order_relaxed);
  const auto snapshot = station.snapshot();
  for (int e = 0; e < endcap_count_ && static_cast<std::size_t>(e) < snapshot.size(); ++e) {
    const ground::EndcapStatus& s = snapshot[static_cast<std::size_t>(e)];
    if (!s.seen || s.heartbeat_host_ns == last_heartbeat_ns_[e]) continue;
    last_heartbeat_ns_[e] = s.heartbeat_host_ns;
    const std::uint32_t life = s.heartbeat.life_id();
    const auto [it, fresh] = life_first_ns_.try_emplace({e, life}, s.heartbeat_host_ns);
    static_cast<void>(fresh);
    const double heard_for_s = static_cast<double>(s.heartbeat_host_ns - it->second) * 1e-9;
    sinks_.table(t_s, e, life, std::string(s.heartbeat.active_policy_id().c_str()), s.heartbeat.active_policy_version(),
                 heard_for_s);
  }
}

}  // namespace tensegrity::hil
