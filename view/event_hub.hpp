// SPDX-License-Identifier: Apache-2.0
#pragma once
// Fan-out of server-sent events: producers (the DDS receive thread, a status timer)
// publish; each connected page's HTTP thread takes everything published since its
// last take, in one write. A page that falls more than the buffer behind skips
// ahead (counted) instead of slowing the producers, which never block on a page.
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>

namespace tensegrity::view {

class EventHub {
 public:
  explicit EventHub(std::size_t capacity = 8192) : capacity_(capacity) {}

  // One event: "event: NAME\ndata: JSON\n\n". `json` must be one line.
  void publish(const std::string& name, const std::string& json);
  // Wakes every waiting reader for good (server shutdown).
  void close();

  // The sequence number a new reader starts after (only events from now on).
  std::uint64_t head() const;
  // Waits up to `timeout_ms` for events after `*cursor`; returns them concatenated
  // (empty on timeout or when closed) and moves the cursor. `skipped` counts events
  // this reader lost by falling behind.
  std::string take(std::uint64_t* cursor, int timeout_ms, std::uint64_t* skipped);
  bool closed() const;
  // Pages connected now (their streams count themselves in and out).
  void reader_joined();
  void reader_left();
  int readers() const;
  // True once a page is connected; false after `timeout_ms`.
  bool wait_for_reader(int timeout_ms) const;

 private:
  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<std::string> events_;
  std::uint64_t first_seq_ = 1;  // sequence number of events_.front()
  bool closed_ = false;
  int readers_ = 0;
  mutable std::condition_variable readers_cv_;
};

}  // namespace tensegrity::view
