// SPDX-License-Identifier: Apache-2.0
#include "view/replay_sink.hpp"

#include "sim/model/model.hpp"

namespace tensegrity::view {

void ReplaySink::begin(const sim::Model& model) {
  builder_ = std::make_unique<ReplayBuilder>(model.robot().node_count(), model.cable_count(), true);
}

void ReplaySink::record(double time_s, const sim::Model& model) {
  if (!builder_->wants(time_s)) return;
  nodes_.clear();
  for (const auto& p : model.node_positions()) nodes_.insert(nodes_.end(), {p.x(), p.y(), p.z()});
  const double energy[3] = {model.kinetic_energy_j(), model.gravity_energy_j(), model.elastic_energy_j()};
  builder_->add(time_s, nodes_, model.rest_length_m(), model.tension_n(), energy);
}

ReplayFrames ReplaySink::take() { return builder_ ? builder_->take() : ReplayFrames{}; }

}  // namespace tensegrity::view
