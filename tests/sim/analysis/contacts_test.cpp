// SPDX-License-Identifier: Apache-2.0
// Ground contacts, faces and slip on a scripted motion of 12 end caps.
#include "sim/analysis/contacts.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "sim/analysis/faces.hpp"

namespace tensegrity::sim::analysis {
namespace {

constexpr double kRadius = 0.03;

// End caps 0, 1, 2 rest on the ground for 1 s while 1 slides along x at 0.5 m/s;
// then 0 lifts 5 cm and 3 comes down: the robot tips onto face (1, 2, 3) for 1 s.
// Everything else is 0.5 m up.
struct Script {
  std::vector<double> time_s;
  std::vector<std::vector<Eigen::Vector3d>> node_m;
  Script() {
    for (int k = 0; k < 200; ++k) {
      const double t = k / 100.0;
      std::vector<Eigen::Vector3d> nodes(12, Eigen::Vector3d(0.0, 0.0, 0.5));
      for (int n = 0; n < 12; ++n) nodes[n].x() = 0.1 * n;
      const bool first = t < 1.0 - 1e-9;
      nodes[0].z() = first ? kRadius - 1e-4 : kRadius + 0.05;
      nodes[1].z() = kRadius + 1e-3;  // within the 2 mm tolerance
      nodes[2].z() = kRadius - 3e-4;
      nodes[3].z() = first ? 0.2 : kRadius;
      nodes[1].x() = 0.1 + 0.5 * std::min(t, 1.0);
      time_s.push_back(t);
      node_m.push_back(nodes);
    }
  }
};

TEST(Contacts, FindsWhichEndCapsTouchAndTheirSlip) {
  const Script s;
  const Contacts c = detect_contacts(s.time_s, s.node_m, kRadius);
  EXPECT_EQ(c.touched(),
            (std::vector<bool>{true, true, true, true, false, false, false, false, false, false, false, false}));
  EXPECT_EQ(c.touched_count(), 4);
  EXPECT_NEAR(c.share[0], 0.5, 1e-9);
  EXPECT_NEAR(c.share[2], 1.0, 1e-9);
  ASSERT_EQ(c.spans[3].size(), 1u);
  EXPECT_NEAR(c.spans[3][0].start_s, 1.0, 1e-9);
  // End cap 1 slides at 0.5 m/s for its first second, then stands; 2 never moves.
  EXPECT_NEAR(c.slip_m_per_s[50][1], 0.5, 1e-9);
  EXPECT_NEAR(c.slip_m_per_s[150][1], 0.0, 1e-9);
  EXPECT_EQ(c.slip_m_per_s[50][5], -1.0);
  const SlipSummary slip = summarize_slip(c, 0);
  EXPECT_NEAR(slip.mean_per_node_m_per_s[1], 0.5 * 100.0 / 199.0, 1e-9);  // 100 of 199 intervals slide
  EXPECT_NEAR(slip.mean_per_node_m_per_s[2], 0.0, 1e-12);
  EXPECT_EQ(slip.mean_per_node_m_per_s[7], -1.0);
}

TEST(Contacts, ShortBreaksAreOneContactLongOnesTwo) {
  std::vector<double> t;
  std::vector<std::vector<Eigen::Vector3d>> p;
  // End cap 0 down, up for 0.05 s (a bounce), down, up for 1 s, down again.
  for (int k = 0; k < 300; ++k) {
    const double time = k / 100.0;
    const bool up = (time >= 0.5 && time < 0.55) || (time >= 1.0 && time < 2.0);
    t.push_back(time);
    p.push_back(std::vector<Eigen::Vector3d>(1, Eigen::Vector3d(0, 0, up ? 0.2 : kRadius)));
  }
  const Contacts c = detect_contacts(t, p, kRadius);
  ASSERT_EQ(c.spans[0].size(), 2u);
  EXPECT_NEAR(c.spans[0][0].end_s, 0.99, 1e-9);
  EXPECT_NEAR(c.spans[0][1].start_s, 2.0, 1e-9);
  EXPECT_EQ(touchdown_intervals(c, 0.0), (std::vector<double>{2.0}));
  EXPECT_TRUE(touchdown_intervals(c, 0.5).empty());
}

TEST(Faces, TheScriptRollsFromOneFaceOntoTheNext) {
  const Script s;
  const Contacts c = detect_contacts(s.time_s, s.node_m, kRadius);
  // Cables 0-1, 1-2, 0-2 close the first face; 1-3 is missing from the second.
  const std::vector<std::pair<int, int>> cables{{0, 1}, {1, 2}, {2, 0}, {2, 3}};
  const auto faces = face_sequence(s.time_s, c, cables, 0.1);
  ASSERT_EQ(faces.size(), 2u);
  EXPECT_EQ(faces[0].nodes, (std::array<int, 3>{0, 1, 2}));
  EXPECT_TRUE(faces[0].closed);
  EXPECT_EQ(faces[1].nodes, (std::array<int, 3>{1, 2, 3}));
  EXPECT_FALSE(faces[1].closed);
  EXPECT_NEAR(faces[1].start_s, 1.0, 1e-9);
}

TEST(Faces, ARepeatingSequenceGivesItsCycleAndPeriod) {
  std::vector<GroundFace> faces;
  const std::array<std::array<int, 3>, 3> band{{{0, 1, 2}, {1, 2, 3}, {2, 3, 4}}};
  for (int i = 0; i < 10; ++i) faces.push_back({band[i % 3], 2.5 * i, 2.5 * i + 2.0, false});
  const FaceCycle cycle = face_cycle(faces);
  EXPECT_EQ(cycle.faces, 3);
  EXPECT_NEAR(cycle.period_s, 7.5, 1e-9);
  EXPECT_NEAR(cycle.match, 1.0, 1e-12);
  EXPECT_EQ(cycle.from_face, 0);
  faces.resize(5);
  faces[3].nodes = {7, 8, 9};  // no repeat: 1 of 2 and 0 of 1 match
  EXPECT_EQ(face_cycle(faces).faces, 0);
}

TEST(Faces, TheCycleIsJudgedFromWhereTheGaitSettles) {
  // Four faces of a start-up that never come back, then a 3-face band nine times.
  std::vector<GroundFace> faces;
  for (int i = 0; i < 4; ++i) faces.push_back({{10 + i, 20 + i, 30 + i}, 1.0 * i, 1.0 * i + 0.5, false});
  const std::array<std::array<int, 3>, 3> band{{{0, 1, 2}, {1, 2, 3}, {2, 3, 4}}};
  for (int i = 0; i < 27; ++i) faces.push_back({band[i % 3], 4.0 + 2.0 * i, 5.0 + 2.0 * i, false});
  const FaceCycle settled = face_cycle(faces);
  EXPECT_EQ(settled.faces, 3);
  EXPECT_EQ(settled.from_face, 4);
  EXPECT_NEAR(settled.from_s, 4.0, 1e-12);
  EXPECT_NEAR(settled.period_s, 6.0, 1e-9);
  EXPECT_NEAR(settled.match, 1.0, 1e-12);
  // Over the whole sequence the start-up costs 4 of 28 visits: no cycle at 0.9 when
  // the gait may not settle first.
  EXPECT_EQ(face_cycle(faces, 0.9, 0.0).faces, 0);
  EXPECT_EQ(face_cycle(faces, 0.9).from_face, 4);
}

}  // namespace
}  // namespace tensegrity::sim::analysis

namespace tensegrity::sim::analysis {
namespace {

// Six end caps rolling with a 3 s revolution; end cap 0 touches down twice in each,
// so its touchdowns are 1.5 s apart, but the pattern repeats every 3 s.
TEST(ContactPeriod, IsThePatternsPeriodNotTheTimeBetweenTouchdowns) {
  std::vector<double> t;
  std::vector<std::vector<Eigen::Vector3d>> p;
  for (int k = 0; k < 1200; ++k) {
    const double time = k / 100.0;
    const double phase = std::fmod(time, 3.0);
    std::vector<Eigen::Vector3d> nodes(6, Eigen::Vector3d(0, 0, 0.3));
    for (int e = 1; e < 6; ++e) {
      if (phase >= 0.6 * (e - 1) && phase < 0.6 * (e - 1) + 1.0) nodes[e].z() = kRadius;
    }
    if (std::fmod(time, 1.5) < 0.4) nodes[0].z() = kRadius;
    t.push_back(time);
    p.push_back(nodes);
  }
  const Contacts c = detect_contacts(t, p, kRadius);
  const auto gaps = touchdown_intervals(c, 0.0);
  EXPECT_NEAR(quantile(gaps, 0.5), 3.0, 1e-9);
  EXPECT_NEAR(touchdown_intervals(Contacts{{}, {c.spans[0]}, {}, {}}, 0.0).front(), 1.5, 1e-9);
  const ContactPeriod period = contact_period(t, c, 0, 0.5);
  EXPECT_NEAR(period.period_s, 3.0, 0.011);
  EXPECT_GT(period.agreement, 0.99);
}

}  // namespace
}  // namespace tensegrity::sim::analysis
