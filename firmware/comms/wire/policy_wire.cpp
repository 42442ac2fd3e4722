// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/wire/policy_wire.hpp"

#include <bit>
#include <cstdio>
#include <vector>

#include "firmware/hal/crc32.hpp"
#include "msgs/dds.hpp"

namespace tensegrity::fw::comms {
namespace {

class LeWriter {
 public:
  void u32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void u64(std::uint64_t v) {
    for (int i = 0; i < 8; ++i) bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }
  void text(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size()));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
  }
  const std::vector<std::uint8_t>& bytes() const { return bytes_; }

 private:
  std::vector<std::uint8_t> bytes_;
};

std::string format(const char* fmt, auto... args) {
  char buffer[200];
  std::snprintf(buffer, sizeof buffer, fmt, args...);
  return buffer;
}

}  // namespace

namespace {
// The checksummed encoding (docs/design/dds.md "Policy checksum").
LeWriter encode(const PolicyTableMsg& msg) {
  LeWriter w;
  w.u32(0x31435054U);  // "TPC1"
  w.u32(static_cast<std::uint32_t>(static_cast<std::int32_t>(msg.endcap_id())));
  w.u32(msg.policy_version());
  w.u32(msg.motor_count());
  w.u32(msg.complexity());
  w.f64(msg.period_s());
  w.f64(msg.phase_offset_s());
  w.u32(static_cast<std::uint32_t>(msg.rest_length_m().size()));
  for (const double v : msg.rest_length_m()) w.f64(v);
  w.text(msg.policy_id().to_string());
  w.text(msg.robot().to_string());
  return w;
}
}  // namespace

std::uint32_t policy_checksum(const PolicyTableMsg& msg) { return crc32(encode(msg).bytes()); }

std::uint64_t policy_digest(const PolicyTableMsg& msg) {
  LeWriter w = encode(msg);
  w.u32(msg.checksum());
  w.u32(msg.force() ? 1U : 0U);
  w.u32(static_cast<std::uint32_t>(static_cast<std::int32_t>(msg.target_endcap())));
  std::uint64_t h = 0xCBF29CE484222325ULL;  // FNV-1a 64
  for (const std::uint8_t b : w.bytes()) h = (h ^ b) * 0x100000001B3ULL;
  return h;
}

PolicyTableMsg make_policy_message(const core::EndcapTable& table, int endcap, const PolicyIdentity& identity,
                                   std::uint32_t upload_sequence) {
  PolicyTableMsg msg;
  msg.format_version(msgs::kFormatVersion);
  msg.upload_sequence(upload_sequence);
  msg.target_endcap(static_cast<std::int16_t>(endcap));
  msg.endcap_id(static_cast<std::int16_t>(endcap));
  msg.policy_id(identity.policy_id);
  msg.policy_version(identity.policy_version);
  msg.force(identity.force);
  msg.robot(identity.robot);
  msg.period_s(table.period_s);
  msg.phase_offset_s(table.phase_offset_s);
  msg.motor_count(table.motor_count);
  msg.complexity(table.complexity);
  std::vector<double> values;
  for (std::uint32_t m = 0; m < table.motor_count && m < core::kMaxMotorsPerEndcap; ++m) {
    for (std::uint32_t k = 0; k < table.complexity && k < core::kMaxComplexity; ++k) {
      values.push_back(table.rest_length_m[m][k]);
    }
  }
  msg.rest_length_m(values);
  msg.checksum(policy_checksum(msg));
  return msg;
}

bool to_endcap_table(const PolicyTableMsg& msg, core::EndcapTable& out) {
  const std::uint32_t motors = msg.motor_count();
  const std::uint32_t complexity = msg.complexity();
  if (motors == 0 || motors > core::kMaxMotorsPerEndcap || complexity == 0 || complexity > core::kMaxComplexity ||
      msg.rest_length_m().size() != static_cast<std::size_t>(motors) * complexity) {
    return false;
  }
  core::EndcapTable t;
  t.motor_count = motors;
  t.complexity = complexity;
  t.period_s = msg.period_s();
  t.phase_offset_s = msg.phase_offset_s();
  for (std::uint32_t m = 0; m < motors; ++m) {
    for (std::uint32_t k = 0; k < complexity; ++k) t.rest_length_m[m][k] = msg.rest_length_m()[m * complexity + k];
  }
  out = t;
  return true;
}

PolicyCheck check_policy(const PolicyTableMsg& msg, const PolicyExpectations& expect) {
  PolicyCheck c;
  auto reject = [&c](PolicyReason reason, std::string text) {
    c.reason = reason;
    c.text = std::move(text);
    return c;
  };
  if (msg.format_version() != msgs::kFormatVersion) {
    return reject(PolicyReason::wrong_format_version,
                  format("message format version %u, this end cap speaks %u", unsigned{msg.format_version()},
                         unsigned{msgs::kFormatVersion}));
  }
  if (msg.endcap_id() != expect.endcap_id) {
    return reject(PolicyReason::wrong_endcap,
                  format("table built for end cap %d, this is end cap %d", int{msg.endcap_id()}, expect.endcap_id));
  }
  if (msg.policy_id().size() == 0) return reject(PolicyReason::bad_policy_id, describe(PolicyReason::bad_policy_id));
  if (!expect.robot.empty() && msg.robot().to_string() != expect.robot) {
    return reject(PolicyReason::wrong_robot, format("table for robot '%s', this end cap belongs to '%s'",
                                                    msg.robot().c_str(), expect.robot.c_str()));
  }
  if (msg.motor_count() != expect.motor_count) {
    return reject(PolicyReason::bad_motor_count,
                  format("table has %u motors, this end cap has %u", msg.motor_count(), expect.motor_count));
  }
  if (msg.complexity() == 0 || msg.complexity() > core::kMaxComplexity) {
    return reject(PolicyReason::bad_complexity,
                  format("complexity %u, expected 1..%zu", msg.complexity(), core::kMaxComplexity));
  }
  if (msg.rest_length_m().size() != static_cast<std::size_t>(msg.motor_count()) * msg.complexity()) {
    return reject(PolicyReason::bad_size, format("%zu rest lengths for %u motors x complexity %u",
                                                 msg.rest_length_m().size(), msg.motor_count(), msg.complexity()));
  }
  const std::uint32_t sum = policy_checksum(msg);
  if (sum != msg.checksum()) {
    return reject(PolicyReason::bad_checksum, format("checksum 0x%08x, table hashes to 0x%08x", msg.checksum(), sum));
  }
  to_endcap_table(msg, c.table);  // sizes checked above
  const core::TableError error = core::validate(c.table, expect.motor_count, expect.limits);
  if (error != core::TableError::none) {
    if (error == core::TableError::value_out_of_limits) {
      return reject(PolicyReason::value_out_of_limits,
                    format("a rest length is outside %.3f..%.3f m", expect.limits.min_rest_length_m,
                           expect.limits.max_rest_length_m));
    }
    return reject(from_table_error(error), core::describe(error));
  }
  c.text = describe(PolicyReason::accepted);
  return c;
}

}  // namespace tensegrity::fw::comms
