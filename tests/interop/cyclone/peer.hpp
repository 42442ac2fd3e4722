// SPDX-License-Identifier: Apache-2.0
// What cyclone_peer does, phase by phase, on one Cyclone participant: wait for
// every addressed end cap's telemetry, count it, upload policy tables and collect
// their acks (re-sending what is unanswered), check the telemetry reports the
// uploaded policy. Each phase prints its findings as one line per fact
// (SEEN, TELEMETRY, ACK, ACTIVE, MEASURE) for the test to read.
#pragma once

#include <cstdint>
#include <map>
#include <random>
#include <vector>

#include "tests/interop/cyclone/cyclone_link.hpp"
#include "tests/interop/cyclone/policy_table.hpp"
#include "tests/interop/cyclone/telemetry_stats.hpp"

namespace tensegrity::interop {

class Peer {
 public:
  // Prints the TOPIC lines (name and type of each topic it uses).
  Peer(int domain, std::uint16_t endcap_mask);

  // Every addressed end cap's telemetry arrived within `timeout_s` (discovery included).
  bool wait_for_telemetry(double timeout_s);
  // Counts telemetry for `seconds`: rates, losses; false if an end cap fell silent
  // or a sample was refused.
  bool listen(double seconds);
  // One table with a wrong checksum to `endcap`: true when it comes back rejected
  // with reason bad_checksum (8), i.e. the end cap checks what we send.
  bool upload_bad_checksum(const PolicyParams& params, int endcap, double timeout_s);
  // A table per end cap; true when every one is acknowledged as accepted. The time
  // from the first write to the last ack in `latency_ms`.
  bool upload(const PolicyParams& params, double timeout_s, double& latency_ms);
  // The end caps' telemetry reports `params`' policy as active.
  bool wait_active(const PolicyParams& params, double timeout_s);
  // From now on only acks that are not acceptances are printed.
  void quiet() { quiet_ = true; }

 private:
  struct Ack {
    bool accepted = false;
    unsigned reason = 0;
  };

  bool addressed(int e) const { return (mask_ & (1U << e)) != 0; }
  void poll(std::int64_t deadline_ns);
  std::map<int, Ack> exchange(const std::map<int, PolicyTableOut*>& tables, double timeout_s);

  CycloneParticipant participant_;
  std::uint16_t mask_;
  dds_entity_t telemetry_ = 0, acks_ = 0, tables_ = 0, waitset_ = 0;
  TelemetryStats stats_;
  std::vector<PolicyAckC> acks_in_;
  std::int64_t started_ns_ = 0;
  std::int64_t last_ack_ns_ = 0;
  bool quiet_ = false;
  // Random, like the ground uploader's: acks of an earlier run left in the end
  // caps' transient-local history cannot match this run's tables.
  std::uint32_t sequence_base_ = static_cast<std::uint32_t>(std::random_device{}() | 0x100U);
};

}  // namespace tensegrity::interop
