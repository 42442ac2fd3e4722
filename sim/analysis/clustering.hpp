// SPDX-License-Identifier: Apache-2.0
#pragma once
// Agglomerative hierarchical clustering with average linkage (UPGMA): the distance
// between two groups is the mean of the distances between their members. Chosen for
// the muscles' correlation matrix because it does not chain (single linkage joins
// groups through one close pair) and its heights read directly as 1 - the mean r
// between two groups.
#include <vector>

#include "sim/analysis/correlation.hpp"

namespace tensegrity::sim::analysis {

// One merge, as scipy.cluster.hierarchy.linkage writes it: leaves are 0..n-1, the
// cluster made by merge k is n + k.
struct Merge {
  int a = 0;
  int b = 0;
  double height = 0.0;
  int size = 0;
};

struct Dendrogram {
  int leaves = 0;
  std::vector<Merge> merges;    // n - 1 of them, in order of increasing height
  std::vector<int> leaf_order;  // leaves left to right, as a dendrogram draws them
};

// `distance` is square, symmetric, finite and non-negative. Ties merge the pair with
// the lowest indices first, so the tree is deterministic.
Dendrogram average_linkage(const Matrix& distance);

// Flat clusters: cut the tree at `height` (groups whose merges all lie at or below it).
// Labels are 0.. in order of each cluster's first leaf in `leaf_order`.
std::vector<int> cut(const Dendrogram& tree, double height);

// 1 - r for every pair: r = 1 at distance 0, anti-phase (r = -1) farthest at 2.
Matrix one_minus(const Matrix& r);

}  // namespace tensegrity::sim::analysis
