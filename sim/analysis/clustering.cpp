// SPDX-License-Identifier: Apache-2.0
#include "sim/analysis/clustering.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

namespace tensegrity::sim::analysis {
namespace {

void validate(const Matrix& d) {
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (d[i].size() != d.size()) throw std::invalid_argument("average_linkage: distance matrix is not square");
    for (std::size_t j = 0; j < d.size(); ++j) {
      if (!std::isfinite(d[i][j]) || d[i][j] < 0.0 || std::fabs(d[i][j] - d[j][i]) > 1e-9) {
        throw std::invalid_argument("average_linkage: distance [" + std::to_string(i) + "][" + std::to_string(j) +
                                    "] is negative, not finite or not symmetric");
      }
    }
  }
}

// Children of cluster id `c` (a leaf has none), left to right.
void collect_leaves(const Dendrogram& tree, int c, std::vector<int>& out) {
  if (c < tree.leaves) {
    out.push_back(c);
    return;
  }
  const Merge& m = tree.merges[static_cast<std::size_t>(c - tree.leaves)];
  collect_leaves(tree, m.a, out);
  collect_leaves(tree, m.b, out);
}

}  // namespace

Dendrogram average_linkage(const Matrix& distance) {
  validate(distance);
  const int n = static_cast<int>(distance.size());
  Dendrogram tree;
  tree.leaves = n;
  if (n == 0) return tree;
  // Active groups: their cluster id and size; `d` between active groups by slot.
  Matrix d = distance;
  std::vector<int> id(static_cast<std::size_t>(n)), size(static_cast<std::size_t>(n), 1);
  std::vector<bool> active(static_cast<std::size_t>(n), true);
  for (int i = 0; i < n; ++i) id[static_cast<std::size_t>(i)] = i;
  for (int step = 0; step < n - 1; ++step) {
    std::size_t bi = 0, bj = 0;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < d.size(); ++i) {
      for (std::size_t j = i + 1; j < d.size(); ++j) {
        if (active[i] && active[j] && d[i][j] < best) {
          best = d[i][j];
          bi = i;
          bj = j;
        }
      }
    }
    const int merged_size = size[bi] + size[bj];
    tree.merges.push_back({std::min(id[bi], id[bj]), std::max(id[bi], id[bj]), best, merged_size});
    // Group bj joins bi: the new group's mean distance to every other group.
    for (std::size_t k = 0; k < d.size(); ++k) {
      if (!active[k] || k == bi || k == bj) continue;
      d[bi][k] = d[k][bi] = (d[bi][k] * size[bi] + d[bj][k] * size[bj]) / merged_size;
    }
    active[bj] = false;
    size[bi] = merged_size;
    id[bi] = n + step;
  }
  collect_leaves(tree, 2 * n - 2, tree.leaf_order);
  return tree;
}

std::vector<int> cut(const Dendrogram& tree, double height) {
  const int n = tree.leaves;
  // Union the leaves of every merge at or below `height`.
  std::vector<int> parent(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) parent[static_cast<std::size_t>(i)] = i;
  std::function<int(int)> root = [&](int x) {
    while (parent[static_cast<std::size_t>(x)] != x) x = parent[static_cast<std::size_t>(x)];
    return x;
  };
  for (std::size_t k = 0; k < tree.merges.size(); ++k) {
    if (tree.merges[k].height > height) continue;
    std::vector<int> leaves;
    collect_leaves(tree, n + static_cast<int>(k), leaves);
    for (const int leaf : leaves) parent[static_cast<std::size_t>(root(leaf))] = root(leaves.front());
  }
  std::vector<int> label(static_cast<std::size_t>(n), -1), label_of_root(static_cast<std::size_t>(n), -1);
  int next = 0;
  for (const int leaf : tree.leaf_order) {
    int& l = label_of_root[static_cast<std::size_t>(root(leaf))];
    if (l < 0) l = next++;
    label[static_cast<std::size_t>(leaf)] = l;
  }
  return label;
}

Matrix one_minus(const Matrix& r) {
  Matrix d = r;
  for (std::size_t i = 0; i < d.size(); ++i) {
    for (std::size_t j = 0; j < d.size(); ++j) d[i][j] = i == j ? 0.0 : std::max(0.0, 1.0 - r[i][j]);
  }
  return d;
}

}  // namespace tensegrity::sim::analysis
