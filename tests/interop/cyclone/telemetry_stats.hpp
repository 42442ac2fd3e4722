// SPDX-License-Identifier: Apache-2.0
// What the Cyclone peer learns from the end caps' telemetry: which end caps it
// hears, how many samples, how many lost (sequence gaps), what each one runs.
// Every sample is checked before it is counted: a sample we cannot interpret
// (other format version, end cap id out of range) is only counted as refused.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "msgs/format_version.hpp"
#include "tests/interop/cyclone/cyclone_link.hpp"

namespace tensegrity::interop {

inline constexpr int kEndcapCount = 12;
using msgs::kFormatVersion;

struct EndcapTelemetry {
  bool seen = false;
  std::int64_t first_ns = 0;  // steady clock at the first sample
  std::uint64_t samples = 0;
  std::uint64_t lost = 0;  // missing sequence numbers
  std::uint32_t last_seq = 0;
  std::uint8_t mode = 0;
  std::string active_policy_id;
  std::uint32_t active_policy_version = 0;
};

// A human-readable reason when `t` cannot be interpreted, else empty.
std::string check_telemetry(const TelemetryC& t);
// The same for an ack.
std::string check_ack(const PolicyAckC& a);

class TelemetryStats {
 public:
  // False when the sample was refused (see check_telemetry).
  bool add(const TelemetryC& t, std::int64_t now_ns);
  const EndcapTelemetry& operator[](int endcap) const { return endcaps_[static_cast<std::size_t>(endcap)]; }
  std::uint64_t refused() const { return refused_; }
  std::string last_refusal() const { return last_refusal_; }
  // True when every end cap in `mask` sent at least one sample.
  bool all_seen(std::uint16_t mask) const;

 private:
  std::array<EndcapTelemetry, kEndcapCount> endcaps_{};
  std::uint64_t refused_ = 0;
  std::string last_refusal_;
};

}  // namespace tensegrity::interop
