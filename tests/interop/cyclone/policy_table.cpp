// SPDX-License-Identifier: Apache-2.0
#include "tests/interop/cyclone/policy_table.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <stdexcept>

#include "firmware/hal/crc32.hpp"
#include "msgs/format_version.hpp"

namespace tensegrity::interop {
namespace {

constexpr std::size_t kMaxText = 64;  // string<64> in PolicyTable.idl

class LittleEndian {
 public:
  void bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const std::uint8_t*>(data);
    out_.insert(out_.end(), p, p + n);
  }
  void u32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void f64(double v) {
    const auto bits = std::bit_cast<std::uint64_t>(v);
    for (int i = 0; i < 8; ++i) out_.push_back(static_cast<std::uint8_t>(bits >> (8 * i)));
  }
  void text(const char* s) {
    const std::size_t n = strnlen(s, kMaxText);
    u32(static_cast<std::uint32_t>(n));
    bytes(s, n);
  }
  const std::vector<std::uint8_t>& data() const { return out_; }

 private:
  std::vector<std::uint8_t> out_;
};

void copy_text(char (&to)[kMaxText + 1], const std::string& from) {
  std::memset(to, 0, sizeof to);
  std::memcpy(to, from.data(), std::min(from.size(), kMaxText));
}

}  // namespace

void validate(const PolicyParams& p) {
  if (p.policy_id.empty() || p.policy_id.size() > kMaxText) throw std::invalid_argument("policy id: 1..64 characters");
  if (p.robot.size() > kMaxText) throw std::invalid_argument("robot: at most 64 characters");
  if (p.motor_count < 1 || p.motor_count > 4) throw std::invalid_argument("motor count: 1..4");
  if (p.complexity < 1 || p.complexity > 16) throw std::invalid_argument("complexity: 1..16");
  if (!(p.period_s > 0.0 && p.period_s < 3600.0)) throw std::invalid_argument("period: (0, 3600) s");
}

std::uint32_t policy_checksum(const PolicyTableC& msg) {
  LittleEndian w;
  w.bytes("TPC1", 4);
  w.u32(static_cast<std::uint32_t>(static_cast<std::int32_t>(msg.endcap_id)));
  w.u32(msg.policy_version);
  w.u32(msg.motor_count);
  w.u32(msg.complexity);
  w.f64(msg.period_s);
  w.f64(msg.phase_offset_s);
  w.u32(msg.rest_length_m._length);
  for (std::uint32_t i = 0; i < msg.rest_length_m._length; ++i) w.f64(msg.rest_length_m._buffer[i]);
  w.text(msg.policy_id);
  w.text(msg.robot);
  return fw::crc32(w.data());
}

PolicyTableOut::PolicyTableOut(const PolicyParams& p, int endcap, std::uint32_t upload_sequence) {
  validate(p);
  msg_.format_version = msgs::kFormatVersion;
  msg_.upload_sequence = upload_sequence;
  msg_.target_endcap = static_cast<std::int16_t>(endcap);
  msg_.endcap_id = static_cast<std::int16_t>(endcap);
  copy_text(msg_.policy_id, p.policy_id);
  msg_.policy_version = p.policy_version;
  msg_.force = p.force;
  copy_text(msg_.robot, p.robot);
  msg_.period_s = p.period_s;
  msg_.phase_offset_s = p.phase_offset_s;
  msg_.motor_count = p.motor_count;
  msg_.complexity = p.complexity;
  for (std::uint32_t i = 0; i < p.motor_count * p.complexity; ++i) {
    values_.push_back(0.85 + 0.05 * static_cast<double>((i + static_cast<std::uint32_t>(endcap)) % 3));
  }
  msg_.checksum = policy_checksum(message());
}

const PolicyTableC& PolicyTableOut::message() {
  // Cyclone serializes from the buffer and never frees it (_release = false).
  msg_.rest_length_m._maximum = static_cast<std::uint32_t>(values_.size());
  msg_.rest_length_m._length = static_cast<std::uint32_t>(values_.size());
  msg_.rest_length_m._buffer = values_.data();
  msg_.rest_length_m._release = false;
  return msg_;
}

}  // namespace tensegrity::interop
