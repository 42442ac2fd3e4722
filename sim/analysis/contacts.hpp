// SPDX-License-Identifier: Apache-2.0
#pragma once
// Which end caps touch the ground and when, and how fast they slide while they do:
// the rolling evidence an episode leaves in its node positions.
#include <Eigen/Core>
#include <vector>

namespace tensegrity::sim::analysis {

struct ContactOptions {
  // An end cap touches when its surface is within this of the ground: the model's
  // soft contact lets a loaded end cap sink a fraction of a millimetre, a lifted one
  // is centimetres up within a tenth of a second.
  double tolerance_m = 0.002;
  // Contacts broken for less than this are one contact (a bounce, a rocking edge).
  double debounce_s = 0.1;
};

struct ContactInterval {
  double start_s = 0.0;
  double end_s = 0.0;
};

struct Contacts {
  std::vector<std::vector<bool>> touching;          // [sample][node], raw
  std::vector<std::vector<ContactInterval>> spans;  // [node], debounced
  std::vector<double> share;                        // [node] share of the samples touching
  // [sample][node] horizontal speed of a touching end cap over the interval ending at
  // this sample (touching at both ends), else -1.
  std::vector<std::vector<double>> slip_m_per_s;
  std::vector<bool> touched() const;
  int touched_count() const;
};

// `node_m` [sample][node]; `time_s` [sample].
Contacts detect_contacts(const std::vector<double>& time_s, const std::vector<std::vector<Eigen::Vector3d>>& node_m,
                         double endcap_radius_m, const ContactOptions& options = {});

// The time between successive touchdowns (debounced contact starts) of the same end
// cap, over every end cap that touched down at least twice after `from_s`: a rolling
// icosahedron sets each end cap of its band down once per revolution.
std::vector<double> touchdown_intervals(const Contacts& contacts, double from_s);

// The revolution period read off the whole contact pattern: the shortest shift in
// [min_s, half the samples from `first`] at which which-end-caps-touch agrees with
// itself as well as at the best shift (within `slack`). An end cap may touch down
// once or twice a revolution, so the time between its touchdowns alone is not the
// period; the pattern of all of them is. `agreement` is the share of (sample, end cap)
// pairs that agree at that shift. Samples are taken as evenly spaced.
struct ContactPeriod {
  double period_s = 0.0;
  double agreement = 0.0;
};
ContactPeriod contact_period(const std::vector<double>& time_s, const Contacts& contacts, std::size_t first,
                             double min_s, double slack = 0.01);

struct SlipSummary {
  double mean_m_per_s = 0.0;
  double median_m_per_s = 0.0;
  double p95_m_per_s = 0.0;
  std::size_t samples = 0;
  std::vector<double> mean_per_node_m_per_s;  // -1 for an end cap that never touched
};
SlipSummary summarize_slip(const Contacts& contacts, std::size_t first_sample);

// The q-quantile (0..1) of `values`, linear between order statistics; NaN when empty.
double quantile(std::vector<double> values, double q);

}  // namespace tensegrity::sim::analysis
