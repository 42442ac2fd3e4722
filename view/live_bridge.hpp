// SPDX-License-Identifier: Apache-2.0
#pragma once
// `tensegrity view --live`: listens to the end caps' telemetry and heartbeats on a
// DDS domain and publishes them to the page as events. Read-only by construction:
// its participant has readers and no writer at all, so it neither commands the end
// caps nor sends a host heartbeat (which would keep their host-loss watchdog
// satisfied while no real host is there). Each telemetry event carries the end
// cap's sample time and the receive time, both on the host clock (CLOCK_MONOTONIC,
// which the end caps synchronize to), so the page can measure its latency.
#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "robot/robot.hpp"
#include "view/event_hub.hpp"

namespace eprosima::fastdds::dds {
class DomainParticipant;
}

namespace tensegrity::view {

inline constexpr int kLiveEndcaps = 12;

struct LiveOptions {
  int domain = 42;
  double status_rate_hz = 4.0;  // per end cap state, fault and heartbeat age
  // Telemetry goes to the page as frames: each end cap's newest sample since the
  // last frame, at this rate. Twelve end caps at 100 Hz were 1200 events a second,
  // more than a software-rendering page parses beside its drawing: its queue grew
  // to seconds (median 367 ms, 95 % 2.5 s from sample to page, measured).
  double frame_rate_hz = 50.0;
  // DDS Security: the listener enclave of a keystore (read-only permissions); empty: unsecured.
  std::filesystem::path enclave_dir;
};

class LiveBridge {
 public:
  LiveBridge(const sim::Robot& robot, const LiveOptions& options, EventHub& hub);
  ~LiveBridge();
  LiveBridge(const LiveBridge&) = delete;
  LiveBridge& operator=(const LiveBridge&) = delete;

  // The end caps' state now, as the "status" event carries it.
  std::string status_json() const;
  static std::int64_t now_ns();
  // For tests: the participant, to check it has no writer.
  eprosima::fastdds::dds::DomainParticipant& participant();
  // From the DDS receive thread: one valid sample (Telemetry_ / Heartbeat_).
  void on_telemetry_sample(const void* sample, std::int64_t received_ns);
  void on_heartbeat_sample(const void* sample, std::int64_t received_ns);

  struct Endcap {
    bool seen = false;
    std::int64_t heartbeat_host_ns = 0;
    int mode = 0;
    int fault = 0;
    std::string policy;
    bool clock_synced = false;
    bool host_lost = false;
    std::uint64_t telemetry = 0;
    std::uint64_t gaps = 0;
    std::uint32_t last_seq = 0;
  };

 private:
  struct Dds;
  void status_loop();
  void publish_frame();  // the pending samples, as one "telemetry" event

  const sim::Robot& robot_;
  LiveOptions options_;
  EventHub& hub_;
  mutable std::mutex mutex_;
  std::array<Endcap, kLiveEndcaps> endcaps_{};
  std::array<std::string, kLiveEndcaps> pending_;  // newest sample not yet framed ("" none)
  std::uint64_t superseded_ = 0;                   // samples replaced by a newer one before their frame
  std::unique_ptr<Dds> dds_;
  std::condition_variable stop_cv_;
  bool stopping_ = false;
  std::thread status_thread_;
};

}  // namespace tensegrity::view
