// SPDX-License-Identifier: Apache-2.0
// Rest length <-> drive position counts through the spool. Sign convention:
// positive counts wind cable onto the spool, so counts grow as the rest length
// shrinks; count 0 is the rest length at homing (initial_rest_length_m).
// A single-layer spool is assumed: the radius does not change as cable winds on.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

namespace tensegrity::fw {

struct SpoolGeometry {
  double spool_radius_m = 0.01;
  // Encoder counts per spool revolution, gearbox included (placeholder: a
  // 4096-count encoder on the 109:1 gearbox; set from the real drive).
  double counts_per_rev = 4096.0 * 109.0;
  double initial_rest_length_m = 1.0;

  bool valid() const { return spool_radius_m > 0.0 && counts_per_rev > 0.0; }
  double counts_per_m() const { return counts_per_rev / (2.0 * std::numbers::pi * spool_radius_m); }

  // Rounded to the nearest count and saturated to the i32 range.
  std::int32_t counts_from_rest_length(double rest_length_m) const {
    return saturate((initial_rest_length_m - rest_length_m) * counts_per_m());
  }
  double rest_length_from_counts(std::int32_t counts) const {
    return initial_rest_length_m - static_cast<double>(counts) / counts_per_m();
  }
  // Lengthening (positive rate) unwinds: negative counts/s.
  std::int32_t counts_per_s_from_rate(double rest_length_rate_m_per_s) const {
    return saturate(-rest_length_rate_m_per_s * counts_per_m());
  }
  double rate_from_counts_per_s(std::int32_t counts_per_s) const {
    return -static_cast<double>(counts_per_s) / counts_per_m();
  }

 private:
  static std::int32_t saturate(double counts) {
    constexpr double lo = std::numeric_limits<std::int32_t>::min();
    constexpr double hi = std::numeric_limits<std::int32_t>::max();
    // NaN must not become a full-range move; callers reject non-finite lengths
    // before this (CanopenMaster::write_target does).
    if (std::isnan(counts)) return 0;
    if (counts <= lo) return std::numeric_limits<std::int32_t>::min();
    if (counts >= hi) return std::numeric_limits<std::int32_t>::max();
    return static_cast<std::int32_t>(std::lround(counts));
  }
};

}  // namespace tensegrity::fw
