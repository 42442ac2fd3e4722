// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/rng.hpp"

#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace tensegrity::sim::evolve {

double Rng::uniform01() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

std::size_t Rng::below(std::size_t n) {
  if (n == 0) throw std::invalid_argument("Rng::below(0)");
  const std::uint64_t bound = n;
  // 2^64 mod n: draws below it would make the low residues more likely.
  const std::uint64_t reject_below = (0 - bound) % bound;
  for (;;) {
    const std::uint64_t r = engine_();
    if (r >= reject_below) return static_cast<std::size_t>(r % bound);
  }
}

double Rng::normal() {
  const double u1 = 1.0 - uniform01();  // (0, 1]: log is finite
  const double u2 = uniform01();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

std::string Rng::state() const {
  std::ostringstream out;
  out << engine_;
  return out.str();
}

void Rng::set_state(const std::string& text) {
  std::istringstream in(text);
  std::mt19937_64 engine;
  in >> engine;
  if (in.fail()) throw std::invalid_argument("not a mt19937_64 state");
  in >> std::ws;
  if (!in.eof()) throw std::invalid_argument("trailing text after the mt19937_64 state");
  engine_ = engine;
}

}  // namespace tensegrity::sim::evolve
