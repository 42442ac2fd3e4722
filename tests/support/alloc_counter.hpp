// SPDX-License-Identifier: Apache-2.0
#pragma once
// Counts heap allocations made by this thread while a scope is alive. Link
// alloc_counter.cpp into a test binary: it replaces the global operator new.
#include <cstddef>

namespace tensegrity::test {

std::size_t allocations_on_this_thread() noexcept;

class AllocationScope {
 public:
  AllocationScope() noexcept : start_(allocations_on_this_thread()) {}
  std::size_t count() const noexcept { return allocations_on_this_thread() - start_; }

 private:
  std::size_t start_;
};

}  // namespace tensegrity::test
