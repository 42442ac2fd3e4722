// SPDX-License-Identifier: Apache-2.0
#include "sim/analysis/correlation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace tensegrity::sim::analysis {
namespace {

// A signal this flat (relative to its mean) is constant to round-off.
constexpr double kFlat = 1e-12;

void require_same_length(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size() || a.size() < 2) {
    throw std::invalid_argument("correlation: signals must have the same length, at least 2 samples");
  }
}

double mean_of(const std::vector<double>& v) {
  double sum = 0.0;
  for (const double x : v) sum += x;
  return sum / static_cast<double>(v.size());
}

// Centred copy and its norm.
std::vector<double> centred(const std::vector<double>& v, double& norm) {
  const double mean = mean_of(v);
  std::vector<double> out(v.size());
  norm = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    out[i] = v[i] - mean;
    norm += out[i] * out[i];
  }
  norm = std::sqrt(norm);
  return out;
}

bool flat(double norm, const std::vector<double>& v) {
  return norm <= kFlat * (1.0 + std::fabs(mean_of(v))) * std::sqrt(static_cast<double>(v.size()));
}

}  // namespace

double pearson(const std::vector<double>& a, const std::vector<double>& b) {
  require_same_length(a, b);
  double na = 0.0, nb = 0.0;
  const auto ca = centred(a, na);
  const auto cb = centred(b, nb);
  if (flat(na, a) || flat(nb, b)) return &a == &b || a == b ? 1.0 : 0.0;
  double dot = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) dot += ca[i] * cb[i];
  return std::clamp(dot / (na * nb), -1.0, 1.0);
}

Matrix correlation_matrix(const Matrix& signals) {
  const std::size_t n = signals.size();
  Matrix r(n, std::vector<double>(n, 1.0));
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) r[i][j] = r[j][i] = pearson(signals[i], signals[j]);
  }
  return r;
}

AlignedCorrelation best_circular_correlation(const std::vector<double>& a, const std::vector<double>& b) {
  require_same_length(a, b);
  double na = 0.0, nb = 0.0;
  const auto ca = centred(a, na);
  const auto cb = centred(b, nb);
  if (flat(na, a) || flat(nb, b)) return {a == b ? 1.0 : 0.0, 0};
  const std::size_t n = a.size();
  AlignedCorrelation best{-2.0, 0};
  for (std::size_t lag = 0; lag < n; ++lag) {
    double dot = 0.0;
    for (std::size_t i = 0; i < n; ++i) dot += ca[i] * cb[(i + lag) % n];
    const double r = dot / (na * nb);
    if (r > best.r + 1e-12) best = {std::clamp(r, -1.0, 1.0), static_cast<int>(lag)};
  }
  return best;
}

AlignedMatrix aligned_correlation_matrix(const Matrix& signals) {
  const std::size_t n = signals.size();
  AlignedMatrix out{Matrix(n, std::vector<double>(n, 1.0)), std::vector<std::vector<int>>(n, std::vector<int>(n, 0))};
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const auto best = best_circular_correlation(signals[i], signals[j]);
      const int len = static_cast<int>(signals[i].size());
      out.r[i][j] = out.r[j][i] = best.r;
      out.lag[i][j] = best.lag;
      out.lag[j][i] = best.lag == 0 ? 0 : len - best.lag;
    }
  }
  return out;
}

}  // namespace tensegrity::sim::analysis
