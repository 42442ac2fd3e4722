// SPDX-License-Identifier: Apache-2.0
#pragma once
// Correlation of the muscles' rest-length signals (Figure 12 of Iscen et al.).
#include <vector>

namespace tensegrity::sim::analysis {

using Matrix = std::vector<std::vector<double>>;

// Pearson's r of two equally long signals. A constant signal has no defined r: it is
// reported as 0 against any other signal (it moves with nothing), 1 against itself.
double pearson(const std::vector<double>& a, const std::vector<double>& b);

// r of every pair of `signals` at zero lag: do the muscles move together?
Matrix correlation_matrix(const Matrix& signals);

// The paper's Figure 12 shifts signals so that their most correlated intervals line
// up: the largest r of `a` with `b` shifted circularly by any whole number of samples,
// for signals that hold a whole number of periods. `lag` is that shift (samples).
struct AlignedCorrelation {
  double r = 0.0;
  int lag = 0;
};
AlignedCorrelation best_circular_correlation(const std::vector<double>& a, const std::vector<double>& b);

// Every pair's best circular r, and the lag at which it occurs ([i][j]: b = signal j).
struct AlignedMatrix {
  Matrix r;
  std::vector<std::vector<int>> lag;
};
AlignedMatrix aligned_correlation_matrix(const Matrix& signals);

}  // namespace tensegrity::sim::analysis
