// SPDX-License-Identifier: Apache-2.0
#include "robot/symmetry.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <utility>

namespace tensegrity::sim {
namespace {

Eigen::Vector3d centre_of(const Robot& robot) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : robot.nodes_m) c += p;
  return c / std::max(1, robot.node_count());
}

// Three end caps whose offsets from the centre span space (the best conditioned
// first found), or none.
std::vector<int> spanning_triple(const std::vector<Eigen::Vector3d>& q) {
  const int n = static_cast<int>(q.size());
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      for (int c = b + 1; c < n; ++c) {
        Eigen::Matrix3d m;
        m << q[a], q[b], q[c];
        if (std::abs(m.determinant()) > 0.1 * q[a].norm() * q[b].norm() * q[c].norm()) return {a, b, c};
      }
    }
  }
  return {};
}

std::string axis_name(const Eigen::Matrix3d& m) {
  static const char* axes[] = {"x", "y", "z"};
  std::string out = "(";
  for (int r = 0; r < 3; ++r) {
    int col = -1;
    for (int c = 0; c < 3; ++c) {
      if (std::abs(std::abs(m(r, c)) - 1.0) < 1e-6)
        col = c;
      else if (std::abs(m(r, c)) > 1e-6)
        return "";
    }
    if (col < 0) return "";
    out += std::string(r ? ", " : "") + (m(r, col) < 0 ? "-" : "") + axes[col];
  }
  return out + ")";
}

using Pair = std::pair<int, int>;
Pair ordered(int a, int b) { return a < b ? Pair{a, b} : Pair{b, a}; }

class Matcher {
 public:
  explicit Matcher(const Robot& robot) : robot_(robot), centre_(centre_of(robot)) {
    double size = 0.0;
    for (const auto& p : robot.nodes_m) {
      q_.push_back(p - centre_);
      size = std::max(size, q_.back().norm());
    }
    tol_ = 1e-6 * std::max(size, 1e-3);
    for (int s = 0; s < static_cast<int>(robot.struts.size()); ++s) {
      struts_.insert(ordered(robot.struts[s].node_a, robot.struts[s].node_b));
    }
    for (int m = 0; m < robot.cable_count(); ++m) {
      cables_[ordered(robot.cables[m].node_a, robot.cables[m].node_b)] = m;
    }
  }
  const std::vector<Eigen::Vector3d>& offsets() const { return q_; }
  double tol() const { return tol_; }

  // The symmetry with this matrix, when it maps the robot onto itself.
  bool complete(const Eigen::Matrix3d& m, Symmetry& out) const {
    const int n = robot_.node_count();
    out.node_map.assign(n, -1);
    std::vector<bool> taken(n, false);
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d image = m * q_[i];
      for (int k = 0; k < n; ++k) {
        if (!taken[k] && (q_[k] - image).norm() < tol_) {
          out.node_map[i] = k;
          taken[k] = true;
          break;
        }
      }
      if (out.node_map[i] < 0) return false;
    }
    for (const auto& s : robot_.struts) {
      if (!struts_.contains(ordered(out.node_map[s.node_a], out.node_map[s.node_b]))) return false;
    }
    out.cable_map.assign(robot_.cable_count(), -1);
    out.owners_follow = true;
    for (int c = 0; c < robot_.cable_count(); ++c) {
      const CableSpec& from = robot_.cables[c];
      const auto it = cables_.find(ordered(out.node_map[from.node_a], out.node_map[from.node_b]));
      if (it == cables_.end()) return false;
      const CableSpec& to = robot_.cables[it->second];
      if (to.stiffness_n_per_m != from.stiffness_n_per_m || to.damping_n_s_per_m != from.damping_n_s_per_m)
        return false;
      out.cable_map[c] = it->second;
      out.owners_follow = out.owners_follow && to.owner == out.node_map[from.owner];
    }
    out.matrix = m;
    return true;
  }

 private:
  const Robot& robot_;
  Eigen::Vector3d centre_;
  std::vector<Eigen::Vector3d> q_;
  double tol_ = 0.0;
  std::set<Pair> struts_;
  std::map<Pair, int> cables_;
};

std::string without_spaces(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c != ' ') out += c;
  }
  return out;
}

}  // namespace

std::vector<Symmetry> symmetry_group(const Robot& robot) {
  const Matcher matcher(robot);
  const auto& q = matcher.offsets();
  const std::vector<int> t = spanning_triple(q);
  std::vector<Symmetry> group;
  if (t.empty()) return group;
  Eigen::Matrix3d from;
  from << q[t[0]], q[t[1]], q[t[2]];
  const Eigen::Matrix3d from_inverse = from.inverse();
  const int n = robot.node_count();
  const double tol = matcher.tol();
  auto same = [tol](double a, double b) { return std::abs(a - b) < tol; };
  for (int a = 0; a < n; ++a) {
    if (!same(q[a].norm(), q[t[0]].norm())) continue;
    for (int b = 0; b < n; ++b) {
      if (b == a || !same((q[b] - q[a]).norm(), (q[t[1]] - q[t[0]]).norm())) continue;
      for (int c = 0; c < n; ++c) {
        if (c == a || c == b || !same((q[c] - q[a]).norm(), (q[t[2]] - q[t[0]]).norm()) ||
            !same((q[c] - q[b]).norm(), (q[t[2]] - q[t[1]]).norm())) {
          continue;
        }
        Eigen::Matrix3d to;
        to << q[a], q[b], q[c];
        const Eigen::Matrix3d m = to * from_inverse;
        if ((m.transpose() * m - Eigen::Matrix3d::Identity()).norm() > 1e-6) continue;
        Symmetry s;
        if (matcher.complete(m, s)) group.push_back(std::move(s));
      }
    }
  }
  // The identity first, then by name, each named by its axes when it can be.
  std::sort(group.begin(), group.end(), [](const Symmetry& x, const Symmetry& y) {
    const bool xi = x.matrix.isIdentity(1e-9), yi = y.matrix.isIdentity(1e-9);
    if (xi != yi) return xi;
    return x.node_map < y.node_map;
  });
  for (std::size_t k = 0; k < group.size(); ++k) {
    group[k].name = axis_name(group[k].matrix);
    if (group[k].name.empty()) group[k].name = "#" + std::to_string(k);
  }
  std::stable_sort(group.begin() + (group.empty() ? 0 : 1), group.end(),
                   [](const Symmetry& x, const Symmetry& y) { return x.name < y.name; });
  return group;
}

const Symmetry& find_symmetry(const std::vector<Symmetry>& group, const std::string& name) {
  const std::string wanted = without_spaces(name);
  std::string names;
  for (const Symmetry& s : group) {
    if (without_spaces(s.name) == wanted || (wanted == "identity" && s.matrix.isIdentity(1e-9))) return s;
    names += (names.empty() ? "" : " ") + without_spaces(s.name);
  }
  throw PolicyError("symmetry \"" + name + "\": not a symmetry of this robot (its symmetries: " + names + ")");
}

Policy image_of(const Policy& policy, const Symmetry& symmetry, const Robot& robot) {
  Policy out = policy;
  for (std::size_t m = 0; m < policy.cables.size(); ++m) {
    const int to = symmetry.cable_map.at(m);
    out.cables[to] = {to, robot.cables[to].owner, policy.cables[m].rest_lengths_m};
  }
  out.provenance.heading_deg.reset();
  out.provenance.symmetry = symmetry.name;
  return out;
}

int face_image(const Symmetry& symmetry, const std::vector<HullFace>& faces, int face) {
  std::array<int, 3> image{};
  for (int k = 0; k < 3; ++k) image[k] = symmetry.node_map.at(faces.at(face).nodes[k]);
  std::sort(image.begin(), image.end());
  for (std::size_t f = 0; f < faces.size(); ++f) {
    if (faces[f].nodes == image) return static_cast<int>(f);
  }
  return -1;
}

Eigen::Matrix2d heading_map(const Symmetry& symmetry, const std::vector<HullFace>& faces, int face) {
  const int image = face_image(symmetry, faces, face);
  // The image face's canonical pose, relabelled, is this map applied to the source
  // face's canonical pose; it keeps the vertical, so its horizontal part is all.
  const Eigen::Matrix3d a =
      face_down_turn(faces.at(image).normal) * symmetry.matrix * face_down_turn(faces.at(face).normal).transpose();
  return a.topLeftCorner<2, 2>();
}

}  // namespace tensegrity::sim
