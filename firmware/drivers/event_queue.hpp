// SPDX-License-Identifier: Apache-2.0
// Fixed-capacity FIFO for events raised on the hot path: no allocation; when full,
// the newest event is dropped and counted (the oldest explain what went wrong first).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace tensegrity::fw::canopen {

template <typename T, std::size_t Capacity>
class EventQueue {
 public:
  bool push(const T& item) {
    if (size_ == Capacity) {
      ++overflows_;
      return false;
    }
    items_[(head_ + size_) % Capacity] = item;
    ++size_;
    return true;
  }
  bool pop(T& item) {
    if (size_ == 0) return false;
    item = items_[head_];
    head_ = (head_ + 1) % Capacity;
    --size_;
    return true;
  }
  std::size_t size() const { return size_; }
  std::uint64_t overflows() const { return overflows_; }

 private:
  std::array<T, Capacity> items_{};
  std::size_t head_ = 0;
  std::size_t size_ = 0;
  std::uint64_t overflows_ = 0;
};

}  // namespace tensegrity::fw::canopen
