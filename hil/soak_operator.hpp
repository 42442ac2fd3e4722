// SPDX-License-Identifier: Apache-2.0
// The chaos soak's operator: a ground station of its own on the run's DDS domain,
// as a console is, that sends the scenario's estops, clear-faults and starts when the
// fault injector hands them over (on the stepper's thread, so it only queues them),
// and listens to every end cap's heartbeat for the table it plays. What it sees goes
// to the soak's sinks from its own thread.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "hil/scenario.hpp"
#include "hil/soak_check.hpp"

namespace tensegrity::ground {
class Station;
}

namespace tensegrity::hil {

struct SoakOperatorSinks {
  // An estop sent at physics time t_s and each end cap's answer (index: end cap).
  std::function<void(double t_s, const std::vector<SoakAck>&)> estop;
  // A new heartbeat: end cap, its life, the table it reports, how long this life was heard.
  std::function<void(double t_s, int endcap, std::uint32_t life, const std::string& policy_id, std::uint32_t version,
                     double heard_for_s)>
      table;
  std::function<void(const std::string&)> log;
};

class SoakOperator {
 public:
  // `enclave_dir` empty: unsecured.
  SoakOperator(int domain, const std::filesystem::path& enclave_dir, int endcap_count, SoakOperatorSinks sinks);
  ~SoakOperator();
  SoakOperator(const SoakOperator&) = delete;
  SoakOperator& operator=(const SoakOperator&) = delete;

  // From the stepper's thread: never blocks on DDS. "" when queued.
  std::string post(const ScenarioEvent& event);
  // The run's physics time, for what the operator observes.
  void set_time(double t_s) { now_s_.store(t_s, std::memory_order_relaxed); }
  // Asks the thread to end (a command in flight is finished first) without waiting:
  // from the stepper's thread before the end caps shut down, so that the station is
  // deleted while their participants live. Fast DDS 2.9 deadlocked here deleting a
  // secured station while the end caps' participants were being removed.
  void finish() {
    stop_ = true;
    wake_.notify_all();
  }
  // finish(), then waits at most `timeout_s` for the thread; false when it did not end
  // (its station's deletion hung): the thread is left running, and this object must
  // then outlive the process (never deleted).
  bool stop(double timeout_s = 10.0);

 private:
  void run(const std::filesystem::path& enclave_dir, int domain);
  void execute(ground::Station& station, const ScenarioEvent& event);
  void observe(ground::Station& station);

  int endcap_count_;
  SoakOperatorSinks sinks_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<ScenarioEvent> queue_;
  std::atomic<bool> estop_queued_{false};
  std::atomic<bool> stop_{false};
  std::mutex done_mutex_;
  std::condition_variable done_cv_;
  bool done_ = false;
  std::atomic<double> now_s_{0.0};
  std::map<int, std::int64_t> last_heartbeat_ns_;
  std::map<std::pair<int, std::uint32_t>, std::int64_t> life_first_ns_;
  std::thread thread_;
};

}  // namespace tensegrity::hil
