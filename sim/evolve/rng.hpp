// SPDX-License-Identifier: Apache-2.0
#pragma once
// The one source of randomness of a coevolution run. std::mt19937_64 is specified
// bit for bit by the standard, but std::uniform_*_distribution and
// std::normal_distribution are not, so the transforms are our own: a run is the same
// on every standard library, and its state can be saved as text and restored.
#include <cstddef>
#include <cstdint>
#include <random>
#include <string>

namespace tensegrity::sim::evolve {

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}

  // In [0, 1), 53 random bits.
  double uniform01();
  // In [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform01(); }
  // In [0, n), unbiased (rejection of the short last block). n > 0.
  std::size_t below(std::size_t n);
  // Standard normal by Box-Muller; one pair of uniforms per value, no cached second
  // value, so the state is the engine's alone.
  double normal();

  // The engine's standard text representation; set_state throws
  // std::invalid_argument on text that is not one.
  std::string state() const;
  void set_state(const std::string& text);

 private:
  std::mt19937_64 engine_;
};

}  // namespace tensegrity::sim::evolve
