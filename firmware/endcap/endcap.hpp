// SPDX-License-Identifier: Apache-2.0
// One end cap as a component with a lifecycle, as ros2_control's hardware
// interfaces and ROS 2 lifecycle nodes have: configure (read the config, open
// storage and restore the table once, open the bus), activate (the DDS node and
// the control-loop thread), run (housekeeping: events, the status line, until
// told to stop), deactivate (loop joined, node stopped). Each step throws
// EndcapError naming what failed; main only sequences them.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>

#include "firmware/app/config.hpp"
#include "firmware/app/control_loop.hpp"
#include "firmware/app/endcap_stats.hpp"
#include "firmware/app/host_link.hpp"
#include "firmware/app/policy_store.hpp"
#include "firmware/hal/can_bus.hpp"
#include "firmware/hal/clock.hpp"
#include "firmware/hal/storage.hpp"

namespace tensegrity::fw::app {

class EndcapError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What the command line says (main.cpp parses it).
struct EndcapOptions {
  int id = -1;
  std::filesystem::path config_path;
  std::filesystem::path policy_path;  // empty: the stored table, if any
  bool start_on_boot = false;
  double duration_s = 0.0;  // 0: until stopped
  bool no_dds = false;
  std::string host_loss = "stop";
  double host_boot_grace_s = 30.0;                       // comms::EndcapNodeConfig::host_boot_grace_s
  double unheard_rejoin_s = 20.0;                        // comms::EndcapNodeConfig::unheard_rejoin_s; 0: never
  int domain = -1;                                       // -1: TENSEGRITY_DOMAIN or the default
  std::filesystem::path keystore;                        // --keystore: overrides the config's dds_keystore
  bool insecure = false;                                 // --insecure: DDS without security, explicitly
  const std::atomic<bool>* link_cut = nullptr;           // --dds-cut-signals
  const std::atomic<std::uint32_t>* dds_mute = nullptr;  // --dds-cut-signals: each one mutes the participant
  const std::atomic<bool>* hang_loop = nullptr;          // --hang-loop-signal (HIL tests only)
  std::filesystem::path stats_path;                      // --stats-json: a snapshot every second while running
};

// The identity `endcap --policy FILE` stores with the file's table: named after
// the file, version 0 (any uploaded version is newer), checksum over the table.
StoredIdentity file_policy_identity(const std::filesystem::path& policy_path, const core::EndcapTable& table);

class Endcap {
 public:
  enum class State : std::uint8_t { unconfigured, inactive, active };

  explicit Endcap(EndcapOptions options);
  ~Endcap();
  Endcap(const Endcap&) = delete;
  Endcap& operator=(const Endcap&) = delete;

  void configure();
  void activate();
  // Housekeeping every 20 ms until `stop` is set or the duration has passed.
  void run(const std::atomic<bool>& stop);
  void deactivate() noexcept;

  // What --stats-json holds: while active, a snapshot from the loop's last published
  // status; once deactivated, the final report (timing, table phase).
  EndcapStats stats() const;

  State state() const { return state_; }
  const EndcapAppConfig& config() const { return config_; }
  const ControlLoop& loop() const { return *loop_; }

 private:
  void restore_or_store_table();
  void start_host_link();
  std::filesystem::path enclave_dir() const;
  void housekeeping();
  LinkEvents link_events() const;

  EndcapOptions options_;
  State state_ = State::unconfigured;
  EndcapAppConfig config_;
  std::unique_ptr<FileStorage> storage_;
  std::unique_ptr<PolicyStore> store_;
  core::EndcapTable table_{};
  bool have_table_ = false;
  std::unique_ptr<CanBus> bus_;
  SystemClock clock_;
  NullHostLink null_host_;
  std::unique_ptr<HostLink> node_;  // the DDS node, when there is one
  std::unique_ptr<ControlLoop> loop_;
  std::atomic<bool> loop_stop_{false};
  // The loop's progress, one per pass (a lockstep wait included): the DDS node's watchdog.
  std::atomic<std::uint64_t> loop_progress_{0};
  std::thread loop_thread_;
  LoopStatus last_status_{};  // the newest the loop published (housekeeping thread)
  std::chrono::steady_clock::time_point next_stats_write_{};
  LinkEvents stats_link_written_{};  // the link's events in the last snapshot written
};

}  // namespace tensegrity::fw::app
