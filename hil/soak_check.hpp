// SPDX-License-Identifier: Apache-2.0
// The chaos soak's invariants (tensegrity soak), judged from what the run observed:
//   tension      no cable above the robot's hard limit (hard_limit_tension_n)
//   estop        every estop acked by every end cap it must reach (running, on the
//                link and settled: SoakTimeline) within the bound
//   table        every end cap heard plays the table uploaded, none loses or mixes it
//   host_loss    an end cap loses its host only when its link was cut
//   memory       every process's resident memory flat once warmed up
//   run          the HIL run itself completed
// Pure: fed by the soak's run (soak_run.hpp), tested with made-up observations.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "hil/soak_plan.hpp"

namespace tensegrity::hil {

struct SoakViolation {
  std::string invariant;
  double time_s = -1.0;  // physics time; -1: the run as a whole
  int endcap = -1;       // -1: none in particular
  std::string detail;
  std::string describe() const;
};

struct SoakAck {
  bool acked = false;
  double latency_s = 0.0;  // from the command's first sending
  // Not acked: whether the end cap's heartbeats (same life) counted one more estop by
  // the end of the command, i.e. it took the stop and only its answer was lost.
  bool taken = false;
  bool heard = false;  // a heartbeat of it was heard at all
};

struct RssSample {
  double time_s = 0.0;  // wall time since the run began
  std::int64_t rss_bytes = 0;
};

struct SoakBounds {
  double tension_limit_n = 500.0;
  double estop_s = 0.5;
  double table_grace_s = 3.0;       // a life heard this long must report its table
  double memory_warmup_s = 30.0;    // of a process's life, before its memory is judged
  double memory_min_span_s = 40.0;  // judged only over at least this long
  std::int64_t memory_slack_bytes = 4 << 20;
  double memory_slack_ratio = 0.10;  // growth allowed: the larger of the two
};

class SoakChecker {
 public:
  SoakChecker(const SoakTimeline& timeline, int endcap_count, const SoakBounds& bounds)
      : timeline_(timeline), endcaps_(endcap_count), bounds_(bounds) {}

  // The model's largest tension so far, after the step at `t_s`.
  void tension(double t_s, double max_tension_n);
  // An estop sent at physics time `t_s`, each end cap's answer (index: end cap).
  void estop(double t_s, const std::vector<SoakAck>& acks);
  // A heartbeat of an end cap's life heard `heard_for_s` after its first (judged
  // from physics step 0: before it the upload is under way).
  void table(double t_s, int endcap, std::uint32_t life, const std::string& policy_id, std::uint32_t version,
             double heard_for_s);
  // At the end: the host losses each end cap counted over all its lives.
  void host_losses(int endcap, std::uint64_t losses);
  // At the end: one process's resident memory over its life.
  void memory(const std::string& process, const std::vector<RssSample>& samples);
  void run_failed(const std::string& error);

  const std::vector<SoakViolation>& violations() const { return violations_; }
  nlohmann::json to_json() const;

 private:
  void add(const std::string& invariant, double t_s, int endcap, const std::string& detail);

  const SoakTimeline& timeline_;
  int endcaps_;
  SoakBounds bounds_;
  std::vector<SoakViolation> violations_;
  std::map<std::string, int> checked_;  // observations per invariant
  double max_tension_n_ = 0.0;
  bool tension_reported_ = false;
  std::vector<double> estop_latencies_s_;  // of the end caps each estop had to reach
  int estops_ = 0;
  std::pair<std::string, std::uint32_t> table_;                   // the first table heard: the run's
  std::map<std::pair<int, std::uint32_t>, bool> table_reported_;  // (end cap, life)
  std::uint64_t losses_ = 0;
  int cuts_ = 0;
  nlohmann::json memory_ = nlohmann::json::array();
};

// Mean of the first and last few samples after the warm-up; empty when the life is
// too short to judge (first: -1).
std::pair<std::int64_t, std::int64_t> rss_start_end(const std::vector<RssSample>& samples, const SoakBounds& bounds);

}  // namespace tensegrity::hil
