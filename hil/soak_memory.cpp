// SPDX-License-Identifier: Apache-2.0
#include "hil/soak_memory.hpp"

#include <unistd.h>

#include <fstream>

namespace tensegrity::hil {

std::int64_t resident_bytes(pid_t pid) {
  std::ifstream statm("/proc/" + std::to_string(pid) + "/statm");
  long size_pages = 0;
  long resident_pages = 0;
  if (!(statm >> size_pages >> resident_pages)) return -1;
  return static_cast<std::int64_t>(resident_pages) * ::sysconf(_SC_PAGESIZE);
}

RssSampler::RssSampler(std::chrono::milliseconds period) : period_(period), start_(std::chrono::steady_clock::now()) {
  for (auto& p : pids_) p.store(0);
  thread_ = std::thread([this] {
    std::unique_lock lock(mutex_);
    while (!stop_) {
      if (active_.load() && !began_) {
        began_ = true;
        start_ = std::chrono::steady_clock::now();
      }
      const double t_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
      if (began_) sample(t_s);
      wake_.wait_for(lock, period_, [this] { return stop_; });
    }
  });
}

RssSampler::~RssSampler() { static_cast<void>(stop()); }

std::map<std::string, std::vector<RssSample>> RssSampler::stop() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  return std::move(series_);
}

void RssSampler::sample(double t_s) {
  const pid_t self = ::getpid();
  if (const auto rss = resident_bytes(self); rss >= 0) {
    series_["tensegrity (pid " + std::to_string(self) + ")"].push_back({t_s, rss});
  }
  for (std::size_t e = 0; e < pids_.size(); ++e) {
    const pid_t pid = pids_[e].load();
    if (pid <= 0) continue;
    // A killed program's pid reads as gone (or as its zombie, 0 pages): no sample.
    if (const auto rss = resident_bytes(pid); rss > 0) {
      series_["endcap " + std::to_string(e) + " (pid " + std::to_string(pid) + ")"].push_back({t_s, rss});
    }
  }
}

}  // namespace tensegrity::hil
