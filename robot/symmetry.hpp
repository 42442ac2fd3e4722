// SPDX-License-Identifier: Apache-2.0
#pragma once
// The robot's symmetries and what they do to a gait. A symmetry is a permutation of
// the end caps that maps struts to struts and cables to cables (with the same
// stiffness and damping) and is an isometry of the description's pose; the model's
// physics cannot tell a pose from its image, so a gait's image under a symmetry,
// played from the image of a pose, rolls the image of the path. The image of a
// policy plays cable m's table on the cable that m's end caps map to, each cable
// still driven by its owner: the end caps play tables as they always do.
#include <Eigen/Core>
#include <Eigen/LU>
#include <string>
#include <vector>

#include "robot/policy.hpp"
#include "robot/robot.hpp"
#include "robot/start_frame.hpp"

namespace tensegrity::sim {

struct Symmetry {
  std::vector<int> node_map;   // end cap i -> node_map[i]
  std::vector<int> cable_map;  // cable m -> cable_map[m]
  // Description frame, about the end caps' centre: p[node_map[i]] - c = matrix (p[i] - c).
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Identity();
  // The image of the description's point (x, y, z), e.g. "(-x, y, z)", when the matrix
  // is a signed permutation of the axes; "#k" (its index in the group) otherwise.
  std::string name;
  bool proper() const { return matrix.determinant() > 0.0; }  // a rotation; else a reflection
  // Cable m's owner maps to the owner of its image for every m: end cap i's whole table
  // moves to end cap node_map[i] (motors in cable order).
  bool owners_follow = false;
};

// Every symmetry, the identity first, the rest by name. Found from the robot's nodes,
// struts and cables: for three end caps spanning space, every choice of images at
// the same distances fixes one orthogonal map, kept when it maps the whole robot
// onto itself (within 1e-6 of the robot's size).
std::vector<Symmetry> symmetry_group(const Robot& robot);

// The symmetry named `name` (spaces ignored), or a PolicyError listing the names.
const Symmetry& find_symmetry(const std::vector<Symmetry>& group, const std::string& name);

// `policy`'s image: cable cable_map[m] plays what cable m played; the provenance is
// kept, its heading dropped (the image's is not the source's) and its symmetry named.
Policy image_of(const Policy& policy, const Symmetry& symmetry, const Robot& robot);

// The hull face `face` is mapped onto (an index into `faces`).
int face_image(const Symmetry& symmetry, const std::vector<HullFace>& faces, int face);

// The horizontal isometry from the start frame of hull face `face` to that of its
// image: a gait that rolls d from `face` in that face's start frame, mapped by the
// symmetry, rolls heading_map * d from the image face in the image's start frame.
// A rotation for a proper symmetry, a reflection otherwise.
Eigen::Matrix2d heading_map(const Symmetry& symmetry, const std::vector<HullFace>& faces, int face);

}  // namespace tensegrity::sim
