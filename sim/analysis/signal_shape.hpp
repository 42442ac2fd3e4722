// SPDX-License-Identifier: Apache-2.0
#pragma once
// The shape of one period of a rest-length signal: the paper (Figure 12) finds half
// of its learned signals with one high and one low per cycle, half with two peaks.
#include <vector>

namespace tensegrity::sim::analysis {

// Peaks in one period of a periodic signal (the samples wrap around): rises of at
// least `prominence` above the lowest value since the last peak, each followed by a
// fall of at least `prominence`. A flat signal has 0.
int peaks_per_period(const std::vector<double>& one_period, double prominence);

}  // namespace tensegrity::sim::analysis
