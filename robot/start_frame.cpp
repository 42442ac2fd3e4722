// SPDX-License-Identifier: Apache-2.0
#include "robot/start_frame.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>
#include <numbers>

namespace tensegrity::sim {
namespace {

Eigen::Vector3d centroid(std::span<const Eigen::Vector3d> p) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& x : p) c += x;
  return p.empty() ? c : Eigen::Vector3d(c / static_cast<double>(p.size()));
}

double rad_to_deg(double rad) { return rad * 180.0 / std::numbers::pi; }

}  // namespace

std::vector<HullFace> hull_faces(const Robot& robot) {
  const int n = robot.node_count();
  const auto& p = robot.nodes_m;
  std::vector<std::vector<bool>> linked(n, std::vector<bool>(n, false));
  for (const auto& c : robot.cables) linked[c.node_a][c.node_b] = linked[c.node_b][c.node_a] = true;
  double scale = 0.0;
  for (const auto& x : p) scale = std::max(scale, x.norm());
  const double eps = 1e-9 * std::max(scale, 1e-3);
  std::vector<HullFace> faces;
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      for (int c = b + 1; c < n; ++c) {
        Eigen::Vector3d normal = (p[b] - p[a]).cross(p[c] - p[a]);
        if (normal.norm() < eps * eps) continue;
        normal.normalize();
        int above = 0, below = 0, on = 0;
        for (int k = 0; k < n; ++k) {
          if (k == a || k == b || k == c) continue;
          const double s = normal.dot(p[k] - p[a]);
          if (s > eps) ++above;
          if (s < -eps) ++below;
          if (std::abs(s) <= eps) ++on;
        }
        if (on > 0 || (above > 0 && below > 0)) continue;
        if (above > 0) normal = -normal;
        faces.push_back({{a, b, c}, normal, linked[a][b] && linked[b][c] && linked[a][c]});
      }
    }
  }
  return faces;
}

Eigen::Matrix3d face_down_turn(const Eigen::Vector3d& outward_normal) {
  return Eigen::Quaterniond::FromTwoVectors(outward_normal, -Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

Eigen::Matrix3d fit_rotation(std::span<const Eigen::Vector3d> from, std::span<const Eigen::Vector3d> to) {
  const Eigen::Vector3d cf = centroid(from), ct = centroid(to);
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < from.size() && i < to.size(); ++i) h += (from[i] - cf) * (to[i] - ct).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  // A reflection fits as well when the points are flat; never return one.
  if ((svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0) d(2, 2) = -1.0;
  return svd.matrixV() * d * svd.matrixU().transpose();
}

StartFrame start_frame(const Robot& robot, const std::vector<HullFace>& faces,
                       std::span<const Eigen::Vector3d> nodes_m) {
  StartFrame f;
  const Eigen::Vector3d c = centroid(nodes_m);
  f.origin_m = {c.x(), c.y()};
  f.body = fit_rotation(robot.nodes_m, nodes_m);
  // The description-frame direction that now points down, and the face nearest it.
  const Eigen::Vector3d down = f.body.transpose() * -Eigen::Vector3d::UnitZ();
  double best = -2.0;
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const double d = faces[i].normal.dot(down);
    if (d > best) {
      best = d;
      f.face = static_cast<int>(i);
    }
  }
  const Eigen::Matrix3d turn = f.face >= 0 ? face_down_turn(faces[f.face].normal) : face_down_turn(down);
  // What is left of the body's rotation after the face is turned down: a turn about
  // the vertical (plus the little tilt of a face not quite flat), read from the x axis.
  const Eigen::Matrix3d yaw = f.body * turn.transpose();
  f.yaw_rad = std::atan2(yaw(1, 0), yaw(0, 0));
  return f;
}

double wrap_deg(double deg) {
  double w = std::fmod(deg, 360.0);
  if (w > 180.0) w -= 360.0;
  if (w <= -180.0) w += 360.0;
  return w;
}

Travel travel(const StartFrame& frame, const Eigen::Vector2d& end_centre_m) {
  Travel t;
  t.world_m = end_centre_m - frame.origin_m;
  const double c = std::cos(frame.yaw_rad), s = std::sin(frame.yaw_rad);
  t.start_m = {c * t.world_m.x() + s * t.world_m.y(), -s * t.world_m.x() + c * t.world_m.y()};
  t.distance_m = t.world_m.norm();
  t.yaw_deg = wrap_deg(rad_to_deg(frame.yaw_rad));
  if (t.distance_m > 0.0) t.heading_deg = wrap_deg(rad_to_deg(std::atan2(t.start_m.y(), t.start_m.x())));
  return t;
}

}  // namespace tensegrity::sim
