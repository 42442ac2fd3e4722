// SPDX-License-Identifier: Apache-2.0
// Lock-free hand-over between the control-loop thread and one other thread
// (housekeeping, logging, the DDS participant). The loop must never wait on a
// mutex held by a thread that may be descheduled, so both sides only ever touch
// atomics and their own buffers. Capacities are fixed: nothing allocates.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace tensegrity::fw::app {

// Latest-value triple buffer: the writer never waits, the reader gets the newest
// complete value (older unread ones are overwritten, as telemetry should be).
template <typename T>
class LatestValue {
  static_assert(std::is_trivially_copyable_v<T>, "copied between threads by value");

 public:
  void write(const T& value) noexcept {
    slots_[write_] = value;
    const std::uint8_t old = middle_.exchange(static_cast<std::uint8_t>(write_ | kFresh), std::memory_order_acq_rel);
    write_ = old & kIndex;
  }
  // False when nothing new was written since the last read.
  bool read(T& out) noexcept {
    if ((middle_.load(std::memory_order_acquire) & kFresh) == 0) return false;
    const std::uint8_t old = middle_.exchange(read_, std::memory_order_acq_rel);
    read_ = old & kIndex;
    out = slots_[read_];
    return true;
  }

 private:
  static constexpr std::uint8_t kFresh = 0x4;
  static constexpr std::uint8_t kIndex = 0x3;
  std::array<T, 3> slots_{};
  std::uint8_t write_ = 0;
  std::uint8_t read_ = 1;
  std::atomic<std::uint8_t> middle_{2};
};

// Single-producer single-consumer FIFO; a push into a full ring is refused and
// counted (the oldest entries are the ones that explain what went wrong).
template <typename T, std::size_t Capacity>
class SpscRing {
  static_assert(std::is_trivially_copyable_v<T>);
  static_assert((Capacity & (Capacity - 1)) == 0, "a power of two keeps the index arithmetic cheap");

 public:
  bool push(const T& item) noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) == Capacity) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    items_[head & (Capacity - 1)] = item;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }
  bool pop(T& item) noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return false;
    item = items_[tail & (Capacity - 1)];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }
  std::uint64_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }

 private:
  std::array<T, Capacity> items_{};
  std::atomic<std::size_t> head_{0};
  std::atomic<std::size_t> tail_{0};
  std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace tensegrity::fw::app
