// SPDX-License-Identifier: Apache-2.0
#include "hil/start_handshake.hpp"

#include <chrono>

#include "hil/clock.hpp"
#include "hil/hil_error.hpp"

namespace tensegrity::hil {

namespace {
std::chrono::nanoseconds until(std::int64_t deadline_ns) {
  return std::chrono::nanoseconds(std::max<std::int64_t>(0, deadline_ns - monotonic_ns()));
}
}  // namespace

FrozenTick StartHandshake::freeze(std::int64_t deadline_ns) {
  std::unique_lock lock(mutex_);
  freeze_requested_ = true;
  changed_.notify_all();
  // Wakes at the deadline at the latest; a failure decided meanwhile ends the wait too.
  changed_.wait_for(lock, until(deadline_ns), [this] { return frozen_.has_value() || decision_.has_value(); });
  if (!frozen_) throw HilError("the world stepper did not stop its SYNCs in time (start handshake)");
  return *frozen_;
}

void StartHandshake::go_after_ticks(std::int64_t ticks) {
  std::lock_guard lock(mutex_);
  Decision d;
  d.after_ticks = ticks < 1 ? 1 : ticks;
  decision_ = d;
  changed_.notify_all();
}

void StartHandshake::go_at(std::int64_t time_ns) {
  std::lock_guard lock(mutex_);
  Decision d;
  d.at_ns = time_ns;
  decision_ = d;
  changed_.notify_all();
}

void StartHandshake::fail(const std::string& reason) {
  std::lock_guard lock(mutex_);
  Decision d;
  d.failed = true;
  d.reason = reason;
  decision_ = d;
  changed_.notify_all();
}

bool StartHandshake::freeze_requested() const {
  std::lock_guard lock(mutex_);
  return freeze_requested_;
}

void StartHandshake::frozen(const FrozenTick& tick) {
  std::lock_guard lock(mutex_);
  frozen_ = tick;
  changed_.notify_all();
}

std::optional<StartHandshake::Decision> StartHandshake::decision(std::int64_t deadline_ns) const {
  std::unique_lock lock(mutex_);
  if (!decision_ && deadline_ns > monotonic_ns()) {
    changed_.wait_for(lock, until(deadline_ns), [this] { return decision_.has_value(); });
  }
  return decision_;
}

}  // namespace tensegrity::hil
