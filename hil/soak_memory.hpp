// SPDX-License-Identifier: Apache-2.0
// The chaos soak's memory watch: once a second, the resident memory (/proc/PID/statm)
// of this process and of every end cap's program of the moment, one series per
// process (a restarted end cap is a new one).
#pragma once

#include <sys/types.h>

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "hil/soak_check.hpp"

namespace tensegrity::hil {

// Resident bytes of a process, -1 when it is gone.
std::int64_t resident_bytes(pid_t pid);

class RssSampler {
 public:
  static constexpr int kMaxEndcaps = 16;
  explicit RssSampler(std::chrono::milliseconds period = std::chrono::milliseconds(1000));
  ~RssSampler();
  RssSampler(const RssSampler&) = delete;
  RssSampler& operator=(const RssSampler&) = delete;

  // From any thread: sampling starts (at physics step 0: the boot's and the link's
  // growth is not a leak). Times are from here.
  void begin() { active_.store(true); }
  // From any thread (the stepper's: one atomic store): end cap `endcap` is program `pid`.
  void set_pid(int endcap, pid_t pid) {
    if (endcap >= 0 && endcap < kMaxEndcaps) pids_[static_cast<std::size_t>(endcap)].store(pid);
  }
  // Ends sampling; the series by process ("tensegrity (pid N)", "endcap 4 (pid N)").
  std::map<std::string, std::vector<RssSample>> stop();

 private:
  void sample(double t_s);

  std::array<std::atomic<pid_t>, kMaxEndcaps> pids_{};
  std::atomic<bool> active_{false};
  bool began_ = false;
  std::chrono::milliseconds period_;
  std::chrono::steady_clock::time_point start_;
  std::map<std::string, std::vector<RssSample>> series_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace tensegrity::hil
