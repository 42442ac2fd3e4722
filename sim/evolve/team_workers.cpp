// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/team_workers.hpp"

#include <exception>
#include <stdexcept>
#include <utility>

namespace tensegrity::sim::evolve {

TeamWorkers::TeamWorkers(TeamFunction function, int threads) : function_(std::move(function)) {
  if (threads < 1) throw std::invalid_argument("TeamWorkers: threads must be at least 1");
  threads_.reserve(static_cast<std::size_t>(threads));
  for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { work(); });
}

TeamWorkers::~TeamWorkers() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
    queue_.clear();
  }
  queued_.notify_all();
  for (auto& t : threads_) t.join();
}

void TeamWorkers::submit(std::uint64_t job, Team team) {
  {
    std::lock_guard lock(mutex_);
    queue_.push_back(Job{job, std::move(team)});
    ++in_flight_;
  }
  queued_.notify_one();
}

std::size_t TeamWorkers::in_flight() const {
  std::lock_guard lock(mutex_);
  return in_flight_;
}

std::vector<TeamWorkers::Finished> TeamWorkers::collect(std::chrono::microseconds wait) {
  std::unique_lock lock(mutex_);
  if (done_.empty() && wait.count() > 0) finished_.wait_for(lock, wait, [this] { return !done_.empty(); });
  std::vector<Finished> out = std::exchange(done_, {});
  in_flight_ -= out.size();
  return out;
}

void TeamWorkers::work() {
  std::unique_lock lock(mutex_);
  for (;;) {
    queued_.wait(lock, [this] { return stop_ || !queue_.empty(); });
    if (stop_) return;
    Job job = std::move(queue_.front());
    queue_.pop_front();
    lock.unlock();
    Finished finished{job.id, {}, {}};
    try {
      finished.result = function_(job.team);
    } catch (const std::exception& e) {
      finished.error = e.what();
      if (finished.error.empty()) finished.error = "evaluation failed";
    } catch (...) {
      finished.error = "evaluation failed (non-standard exception)";
    }
    lock.lock();
    done_.push_back(std::move(finished));
    finished_.notify_all();
  }
}

}  // namespace tensegrity::sim::evolve
