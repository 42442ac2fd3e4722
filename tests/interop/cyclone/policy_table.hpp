// SPDX-License-Identifier: Apache-2.0
// A policy table for one end cap in Cyclone's C type, with the checksum computed
// from docs/design/dds.md "Policy checksum" (written again here on purpose: an end cap
// accepting it shows the documented encoding is the one the firmware checks).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tests/interop/cyclone/cyclone_link.hpp"

namespace tensegrity::interop {

struct PolicyParams {
  std::string policy_id = "cyclone_peer";
  std::uint32_t policy_version = 1;
  std::string robot = "superball";
  std::uint32_t motor_count = 2;
  std::uint32_t complexity = 4;
  double period_s = 2.0;
  double phase_offset_s = 0.0;
  bool force = false;
};

// Throws std::invalid_argument naming the field when a parameter does not fit the
// IDL's bounds (ids 1..64 chars, 1..4 motors, complexity 1..16).
void validate(const PolicyParams& params);

// CRC-32 over the documented little-endian encoding of `msg`.
std::uint32_t policy_checksum(const PolicyTableC& msg);

class PolicyTableOut {
 public:
  // Table for end cap `endcap`, addressed to it, rest lengths 0.85..0.95 m.
  PolicyTableOut(const PolicyParams& params, int endcap, std::uint32_t upload_sequence);
  // The C message; its sequence points into this object, so valid while it lives.
  const PolicyTableC& message();
  void corrupt_checksum() { msg_.checksum ^= 0x1U; }

 private:
  PolicyTableC msg_{};
  std::vector<double> values_;
};

}  // namespace tensegrity::interop
