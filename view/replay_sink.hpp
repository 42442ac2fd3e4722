// SPDX-License-Identifier: Apache-2.0
#pragma once
// An episode's telemetry straight into replay frames, for runs the view makes
// itself (the best team of an evolution): no CSV in between.
#include <memory>

#include "sim/model/telemetry.hpp"
#include "view/replay_data.hpp"

namespace tensegrity::view {

class ReplaySink final : public sim::TelemetrySink {
 public:
  void begin(const sim::Model& model) override;
  void record(double time_s, const sim::Model& model) override;
  ReplayFrames take();

 private:
  std::unique_ptr<ReplayBuilder> builder_;
  std::vector<double> nodes_;
};

}  // namespace tensegrity::view
