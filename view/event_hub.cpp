// SPDX-License-Identifier: Apache-2.0
#include "view/event_hub.hpp"

#include <chrono>

namespace tensegrity::view {

void EventHub::publish(const std::string& name, const std::string& json) {
  std::string event = "event: " + name + "\ndata: " + json + "\n\n";
  {
    std::lock_guard lock(mutex_);
    events_.push_back(std::move(event));
    if (events_.size() > capacity_) {
      events_.pop_front();
      ++first_seq_;
    }
  }
  cv_.notify_all();
}

void EventHub::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  cv_.notify_all();
}

bool EventHub::closed() const {
  std::lock_guard lock(mutex_);
  return closed_;
}

void EventHub::reader_joined() {
  {
    std::lock_guard lock(mutex_);
    ++readers_;
  }
  readers_cv_.notify_all();
}

void EventHub::reader_left() {
  std::lock_guard lock(mutex_);
  --readers_;
}

int EventHub::readers() const {
  std::lock_guard lock(mutex_);
  return readers_;
}

bool EventHub::wait_for_reader(int timeout_ms) const {
  std::unique_lock lock(mutex_);
  return readers_cv_.wait_for(lock, std::chrono::milliseconds(timeout_ms), [this] { return readers_ > 0; });
}

std::uint64_t EventHub::head() const {
  std::lock_guard lock(mutex_);
  return first_seq_ + events_.size() - 1;
}

std::string EventHub::take(std::uint64_t* cursor, int timeout_ms, std::uint64_t* skipped) {
  std::unique_lock lock(mutex_);
  const auto end_seq = [this] { return first_seq_ + events_.size() - 1; };
  cv_.wait_for(lock, std::chrono::milliseconds(timeout_ms), [&] { return closed_ || end_seq() > *cursor; });
  std::string out;
  if (closed_) return out;
  if (*cursor + 1 < first_seq_) {
    *skipped += first_seq_ - (*cursor + 1);
    *cursor = first_seq_ - 1;
  }
  for (std::uint64_t s = *cursor + 1; s <= end_seq(); ++s) out += events_[s - first_seq_];
  *cursor = end_seq();
  return out;
}

}  // namespace tensegrity::view
