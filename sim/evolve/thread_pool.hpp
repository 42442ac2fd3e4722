// SPDX-License-Identifier: Apache-2.0
#pragma once
// A fixed set of workers that run one indexed batch at a time. Workers live as long
// as the pool, so per-thread set-up (ODE's thread data) is paid once, not per batch.
#include <condition_variable>
#include <cstdint>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace tensegrity::sim::evolve {

class ThreadPool {
 public:
  // threads <= 1: no workers, batches run on the calling thread.
  explicit ThreadPool(int threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  // Calls task(i) once for every i in [0, count) and returns when all are done.
  // The first exception a task throws is rethrown here (the rest of the batch still
  // runs to completion, so no worker is left touching the caller's data).
  void run(std::size_t count, const std::function<void(std::size_t)>& task);
  int threads() const { return workers_.empty() ? 1 : static_cast<int>(workers_.size()); }

 private:
  void work();

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_;
  std::condition_variable done_;
  const std::function<void(std::size_t)>* task_ = nullptr;
  std::size_t count_ = 0;
  std::size_t next_ = 0;
  std::size_t busy_ = 0;
  std::uint64_t batch_ = 0;
  bool stop_ = false;
  std::exception_ptr error_;
};

}  // namespace tensegrity::sim::evolve
