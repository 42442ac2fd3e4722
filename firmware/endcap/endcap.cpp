// SPDX-License-Identifier: Apache-2.0
#include "firmware/endcap/endcap.hpp"

#include <pthread.h>
#include <sched.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <string>

#include "firmware/endcap/endcap_log.hpp"
#include "firmware/app/policy_file.hpp"
#include "firmware/hal/crc32.hpp"
#include "firmware/hal/make_can_bus.hpp"
#ifdef TENSEGRITY_ENDCAP_DDS
#include "firmware/comms/node/endcap_node.hpp"
#include "msgs/dds.hpp"
#include "msgs/security.hpp"
#endif

namespace tensegrity::fw::app {
namespace {

// Real-time priority when allowed (root or CAP_SYS_NICE, as the systemd unit
// grants); otherwise the loop runs at normal priority and says so.
void try_realtime_priority(std::thread& thread) {
  sched_param param{};
  param.sched_priority = 80;
  const int rc = pthread_setschedparam(thread.native_handle(), SCHED_FIFO, &param);
  if (rc != 0) log_line("SCHED_FIFO not available (%s): loop runs at normal priority", std::strerror(rc));
}

long vm_rss_kb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

TimingStats timing_stats(const TimingSummary& t) {
  return {t.count, static_cast<double>(t.p50_ns) * 1e-3, static_cast<double>(t.p99_ns) * 1e-3,
          static_cast<double>(t.max_ns) * 1e-3};
}

}  // namespace

StoredIdentity file_policy_identity(const std::filesystem::path& policy_path, const core::EndcapTable& table) {
  StoredIdentity identity;
  identity.policy_id = ("file:" + policy_path.stem().string()).substr(0, kMaxStoredPolicyIdBytes);
  identity.policy_version = 0;
  identity.checksum = crc32(encode_table(StoredTable{0, table, {}}));
  return identity;
}

Endcap::Endcap(EndcapOptions options) : options_(std::move(options)) { set_log_endcap_id(options_.id); }

Endcap::~Endcap() { deactivate(); }

void Endcap::configure() {
  if (state_ != State::unconfigured) return;
  try {
    config_ = load_config(options_.config_path, options_.id);
  } catch (const std::exception& e) {
    throw EndcapError(e.what());
  }
  if (options_.start_on_boot) config_.start_on_boot = true;
  // Said at every start, so a bench setting that reaches the robot is seen.
  if (!config_.use_load_cell) {
    log_line(
        "WARNING: tension guard OFF (%s: \"tension_guard\": \"off\"): no load cell, cable tension is not "
        "measured, cutoff_tension_n and hard_limit_tension_n are not enforced",
        options_.config_path.c_str());
  }
  std::error_code ec;
  std::filesystem::create_directories(config_.storage_dir, ec);
  if (ec) {
    throw EndcapError(options_.config_path.string() + ": storage_dir: cannot create " + config_.storage_dir.string() +
                      ": " + ec.message());
  }
  storage_ = std::make_unique<FileStorage>(config_.storage_dir);
  store_ = std::make_unique<PolicyStore>(*storage_, config_.motor_count, config_.limits);
  restore_or_store_table();
  MakeCanBusResult bus = make_can_bus(config_.bus);
  if (!bus) throw EndcapError(options_.config_path.string() + ": bus: " + bus.error);
  bus_ = std::move(bus.bus);
  state_ = State::inactive;
}

// The store is read once; --policy FILE replaces its record (table and identity
// together), so a later upload is judged against what actually plays.
void Endcap::restore_or_store_table() {
  StoredTable stored;
  std::string report;
  const bool restored = store_->load(stored, report);
  if (!report.empty()) log_line("policy store: %s", report.c_str());
  if (!options_.policy_path.empty()) {
    try {
      table_ = load_endcap_table(options_.policy_path, options_.id, config_.motor_count, config_.limits);
    } catch (const std::exception& e) {
      throw EndcapError(e.what());
    }
    have_table_ = true;
    std::string error;
    const StoredIdentity identity = file_policy_identity(options_.policy_path, table_);
    if (store_->save(table_, identity, error) != StorageResult::ok) {
      log_line("could not store the policy: %s", error.c_str());
    }
    log_line("policy %s loaded and stored as %s", options_.policy_path.c_str(), identity.policy_id.c_str());
  } else if (restored) {
    table_ = stored.table;
    have_table_ = true;
    log_line("restored table generation %llu (%s v%u)", static_cast<unsigned long long>(stored.generation),
             stored.identity.policy_id.empty() ? "no identity" : stored.identity.policy_id.c_str(),
             stored.identity.policy_version);
  } else {
    log_line("no stored table: idle until one arrives");
  }
}

#ifdef TENSEGRITY_ENDCAP_DDS
// An end cap that obeys whoever is on the Wi-Fi must be a choice, never an
// accident: without a keystore the DDS link needs an explicit --insecure.
std::filesystem::path Endcap::enclave_dir() const {
  if (options_.insecure) {
    log_line("DDS security OFF (--insecure): any participant on domain may command this end cap");
    return {};
  }
  const std::filesystem::path keystore = !options_.keystore.empty() ? options_.keystore : config_.dds_keystore;
  if (keystore.empty()) {
    throw EndcapError("no DDS Security keystore: set \"dds_keystore\" in " + options_.config_path.string() +
                      " or pass --keystore DIR (tensegrity security init), or run without security with --insecure");
  }
  const std::filesystem::path dir = msgs::enclave_dir(keystore, msgs::enclave_name(msgs::Role::endcap, options_.id));
  log_line("DDS security: enclave %s", dir.c_str());
  return dir;
}
#endif

void Endcap::start_host_link() {
#ifdef TENSEGRITY_ENDCAP_DDS
  if (options_.no_dds) return;
  // The DDS node runs on its own threads and meets the loop only in mailboxes.
  try {
    comms::EndcapNodeConfig node_config;
    node_config.endcap_id = options_.id;
    node_config.domain = options_.domain >= 0 ? options_.domain : msgs::domain_id();
    node_config.expect.motor_count = config_.motor_count;
    node_config.expect.limits = config_.limits;
    node_config.host_loss = comms::parse_host_loss_action(options_.host_loss);
    node_config.host_boot_grace_s = options_.host_boot_grace_s;
    node_config.unheard_rejoin_s = options_.unheard_rejoin_s;
    if (config_.mode == LoopMode::lockstep) {
      node_config.start_grid_ns = comms::kLockstepStartGridPeriods * config_.loop_period_ns;
    }
    node_config.link_cut = options_.link_cut;
    node_config.mute_requests = options_.dds_mute;
    node_config.enclave_dir = enclave_dir();
    node_config.loop_progress = &loop_progress_;
    auto node = std::make_unique<comms::EndcapNode>(node_config, clock_, store_.get());
    node->start();
    node_ = std::move(node);
  } catch (const std::exception& e) {
    throw EndcapError(std::string("DDS: ") + e.what());
  }
#endif
}

void Endcap::activate() {
  if (state_ != State::inactive) return;
  start_host_link();
  HostLink& host = node_ ? *node_ : static_cast<HostLink&>(null_host_);
  loop_ = std::make_unique<ControlLoop>(*bus_, clock_, host, make_loop_settings(config_));
  if (have_table_ && loop_->load_table(table_) != core::TableError::none) {
    log_line("stored table rejected by the core");  // cannot happen: validated when stored
  }
  log_line("bus %s, %u motor(s), %s every %lld us%s", config_.bus.c_str(), config_.motor_count, to_string(config_.mode),
           static_cast<long long>(config_.loop_period_ns / 1'000), config_.start_on_boot ? ", start on boot" : "");
  loop_stop_.store(false);
  loop_thread_ = std::thread([this] {
    while (!loop_stop_.load(std::memory_order_relaxed)) {
      if (options_.hang_loop != nullptr && options_.hang_loop->load(std::memory_order_relaxed)) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));  // the test hook: hung, until asked to exit
        continue;
      }
      loop_progress_.fetch_add(1, std::memory_order_relaxed);
      if (config_.mode == LoopMode::realtime) {
        loop_->run_realtime_cycle();
      } else {
        loop_->run_lockstep_cycle(100'000'000);
      }
    }
  });
  // Lockstep: the emulator's SYNC owns the loop's time and no deadline is on the wall
  // clock, so SCHED_FIFO buys only speed, and twelve loops at it beside the stepper
  // keep both cores of a small host busy: the DDS threads, the host watch's included,
  // then starve for a second and the end caps judge a live host lost.
  if (config_.mode == LoopMode::realtime) {
    try_realtime_priority(loop_thread_);
  } else {
    log_line("lockstep: the loop runs at normal priority (SYNC paces it; the DDS threads keep their share)");
  }
  state_ = State::active;
}

void Endcap::housekeeping() {
  AppEvent event;
  while (loop_->pop_event(event)) log_event(event);
  if (loop_->read_status(last_status_)) log_status(last_status_);
  // At once, then once a second: the counts as of the loop's last status line, the
  // link's events as they are now. A link event is written within this pass, not up
  // to a second later: a program killed soon after a cut must still have it on disk.
  const auto now = std::chrono::steady_clock::now();
  const LinkEvents link = link_events();
  if (!options_.stats_path.empty() && (now >= next_stats_write_ || link != stats_link_written_)) {
    next_stats_write_ = now + std::chrono::seconds(1);
    stats_link_written_ = link;
    if (!write_stats(options_.stats_path, stats())) log_line("could not write %s", options_.stats_path.c_str());
  }
}

LinkEvents Endcap::link_events() const { return node_ ? node_->link_events() : LinkEvents{}; }

EndcapStats Endcap::stats() const {
  EndcapStats out;
  out.final = state_ != State::active;
  out.endcap = config_.endcap_id;
  out.mode = to_string(config_.mode);
  out.rate_hz = 1e9 / static_cast<double>(config_.loop_period_ns);
  out.vm_rss_kb = vm_rss_kb();
  out.link = link_events();
  if (!loop_) return out;
  // Active: the loop thread owns its status; read what it last published.
  const LoopStatus& s = out.final ? loop_->status() : last_status_;
  out.cycles = s.cycles;
  out.overruns = s.overruns;
  out.stalls = s.stalls;
  out.late_wakeups = s.late_wakeups;
  out.syncs_received = s.syncs_received;
  out.send_failures = s.send_failures;
  out.rx_drops = s.rx_drops;
  out.drain_limited_cycles = s.drain_limited_cycles;
  out.fault = core::describe(s.fault);
  out.bring_up = canopen::to_string(s.bring_up);
  if (!out.final) return out;
  const ControlLoop& loop = *loop_;
  out.fault = core::describe(loop.controller().fault());
  out.bring_up = canopen::to_string(loop.master().bring_up_step());
  out.cycle = timing_stats(loop.cycle_histogram().summary());
  out.wakeup_latency = timing_stats(loop.wakeup_histogram().summary());
  const core::EndcapController& ctl = loop.controller();
  if (ctl.mode() == core::Mode::running) {
    TablePhase t;
    t.period_s = ctl.active_table().period_s;
    t.loop_time_ns = s.time_ns;
    t.table_time_ns = ctl.table_time_ns(s.time_ns);
    t.origin_loop_ns = s.time_ns - t.table_time_ns;
    if (config_.mode == LoopMode::realtime) t.loop_clock_origin_ns = loop.clock_origin_ns();
    out.table = t;
  }
  return out;
}

void Endcap::run(const std::atomic<bool>& stop) {
  if (state_ != State::active) return;
  const auto started = std::chrono::steady_clock::now();
  for (;;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    housekeeping();
    const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    if (stop.load() || (options_.duration_s > 0.0 && elapsed_s >= options_.duration_s)) break;
  }
}

void Endcap::deactivate() noexcept {
  if (state_ != State::active) return;
  loop_stop_.store(true);
  if (loop_thread_.joinable()) loop_thread_.join();
#ifdef TENSEGRITY_ENDCAP_DDS
  if (node_) static_cast<comms::EndcapNode&>(*node_).stop();
#endif
  AppEvent event;
  while (loop_->pop_event(event)) log_event(event);
  state_ = State::inactive;
}

}  // namespace tensegrity::fw::app
