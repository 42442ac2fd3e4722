// SPDX-License-Identifier: Apache-2.0
#pragma once
// The ground faces an episode rolls over: the triangles of exactly three end caps on
// the ground, in order, and the revolution period their sequence repeats with.
#include <array>
#include <utility>
#include <vector>

#include "sim/analysis/contacts.hpp"

namespace tensegrity::sim::analysis {

struct GroundFace {
  std::array<int, 3> nodes{};  // increasing
  double start_s = 0.0;
  double end_s = 0.0;
  bool closed = false;  // all three edges are cables (one of the icosahedron's 8 closed triangles)
};

// Runs of samples with exactly the same three end caps touching, at least
// `min_duration_s` long; a face that follows itself (after a short interruption) is
// one visit.
std::vector<GroundFace> face_sequence(const std::vector<double>& time_s, const Contacts& contacts,
                                      const std::vector<std::pair<int, int>>& cable_nodes, double min_duration_s);

struct FaceCycle {
  int faces = 0;          // faces per cycle, 0 when the sequence does not repeat
  double period_s = 0.0;  // mean time from a face to its next visit one cycle later
  double match = 0.0;     // share of the visits a cycle later that are the same face
  int from_face = 0;      // the cycle is judged from this face of the sequence on
  double from_s = 0.0;    // ... which the robot reached at this time
};
// The shortest cycle length L >= 2 with which face i equals face i + L for at least
// `min_match` of the visits (an icosahedron rolling straight revisits a band of faces).
// A gait can take a revolution or two to settle from the start pose: the search may
// start at any face within the first `max_settle_share` of the sequence (two cycles
// must follow), and the cycle found is judged from the first face its next cycle
// repeats: where the gait settled.
FaceCycle face_cycle(const std::vector<GroundFace>& faces, double min_match = 0.8, double max_settle_share = 1.0 / 3);

}  // namespace tensegrity::sim::analysis
