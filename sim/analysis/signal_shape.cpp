// SPDX-License-Identifier: Apache-2.0
#include "sim/analysis/signal_shape.hpp"

#include <algorithm>

namespace tensegrity::sim::analysis {

int peaks_per_period(const std::vector<double>& v, double prominence) {
  if (v.empty()) return 0;
  // Start at the global minimum: a full cycle from there sees every peak rise and fall.
  const std::size_t n = v.size();
  const std::size_t start = static_cast<std::size_t>(std::min_element(v.begin(), v.end()) - v.begin());
  int peaks = 0;
  bool rising = true;
  double low = v[start], high = v[start];
  for (std::size_t i = 1; i <= n; ++i) {
    const double x = v[(start + i) % n];
    if (rising) {
      low = std::min(low, x);
      if (x - low >= prominence) {
        rising = false;
        high = x;
      }
    } else {
      high = std::max(high, x);
      if (high - x >= prominence) {
        ++peaks;
        rising = true;
        low = x;
      }
    }
  }
  return peaks;
}

}  // namespace tensegrity::sim::analysis
