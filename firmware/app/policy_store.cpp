// SPDX-License-Identifier: Apache-2.0
#include "firmware/app/policy_store.hpp"

#include <algorithm>
#include <bit>
#include <cstring>

namespace tensegrity::fw::app {
namespace {

constexpr std::uint8_t kMagicV1[4] = {'E', 'T', 'B', '1'};
constexpr std::uint8_t kMagic[4] = {'E', 'T', 'B', '2'};

void put_u64(std::vector<std::uint8_t>& out, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void put_f64(std::vector<std::uint8_t>& out, double v) { put_u64(out, std::bit_cast<std::uint64_t>(v)); }

class Cursor {
 public:
  explicit Cursor(const std::vector<std::uint8_t>& b) : b_(b) {}
  bool u64(std::uint64_t& v) {
    if (pos_ + 8 > b_.size()) return false;
    v = 0;
    for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(b_[pos_ + i]) << (8 * i);
    pos_ += 8;
    return true;
  }
  bool u32(std::uint32_t& v) {
    std::uint64_t w = 0;
    if (pos_ + 4 > b_.size()) return false;
    for (int i = 0; i < 4; ++i) w |= static_cast<std::uint64_t>(b_[pos_ + i]) << (8 * i);
    pos_ += 4;
    v = static_cast<std::uint32_t>(w);
    return true;
  }
  bool f64(double& v) {
    std::uint64_t w = 0;
    if (!u64(w)) return false;
    v = std::bit_cast<double>(w);
    return true;
  }
  bool bytes(std::size_t n, std::string& out) {
    if (n > b_.size() - pos_) return false;
    out.assign(b_.begin() + static_cast<std::ptrdiff_t>(pos_), b_.begin() + static_cast<std::ptrdiff_t>(pos_ + n));
    pos_ += n;
    return true;
  }
  bool at_end() const { return pos_ == b_.size(); }

 private:
  const std::vector<std::uint8_t>& b_;
  std::size_t pos_ = 4;
};

}  // namespace

std::vector<std::uint8_t> encode_table(const StoredTable& s) {
  std::vector<std::uint8_t> out(kMagic, kMagic + 4);
  put_u64(out, s.generation);
  put_u32(out, s.table.motor_count);
  put_u32(out, s.table.complexity);
  put_f64(out, s.table.period_s);
  put_f64(out, s.table.phase_offset_s);
  for (std::uint32_t m = 0; m < s.table.motor_count && m < core::kMaxMotorsPerEndcap; ++m) {
    for (std::uint32_t j = 0; j < s.table.complexity && j < core::kMaxComplexity; ++j) {
      put_f64(out, s.table.rest_length_m[m][j]);
    }
  }
  const std::string& id = s.identity.policy_id;
  const std::size_t id_bytes = std::min(id.size(), kMaxStoredPolicyIdBytes);
  put_u32(out, s.identity.policy_version);
  put_u32(out, s.identity.checksum);
  put_u32(out, static_cast<std::uint32_t>(id_bytes));
  out.insert(out.end(), id.begin(), id.begin() + static_cast<std::ptrdiff_t>(id_bytes));
  return out;
}

bool decode_table(const std::vector<std::uint8_t>& bytes, StoredTable& out) {
  if (bytes.size() < 4) return false;
  const bool v1 = std::memcmp(bytes.data(), kMagicV1, 4) == 0;
  if (!v1 && std::memcmp(bytes.data(), kMagic, 4) != 0) return false;
  Cursor c(bytes);
  StoredTable s;
  if (!c.u64(s.generation) || !c.u32(s.table.motor_count) || !c.u32(s.table.complexity) || !c.f64(s.table.period_s) ||
      !c.f64(s.table.phase_offset_s)) {
    return false;
  }
  if (s.table.motor_count > core::kMaxMotorsPerEndcap || s.table.complexity > core::kMaxComplexity) return false;
  for (std::uint32_t m = 0; m < s.table.motor_count; ++m) {
    for (std::uint32_t j = 0; j < s.table.complexity; ++j) {
      if (!c.f64(s.table.rest_length_m[m][j])) return false;
    }
  }
  if (!v1) {
    std::uint32_t id_bytes = 0;
    if (!c.u32(s.identity.policy_version) || !c.u32(s.identity.checksum) || !c.u32(id_bytes) ||
        id_bytes > kMaxStoredPolicyIdBytes || !c.bytes(id_bytes, s.identity.policy_id)) {
      return false;
    }
  }
  if (!c.at_end()) return false;
  out = s;
  return true;
}

bool PolicyStore::load(StoredTable& out, std::string& report) {
  report.clear();
  bool found = false;
  for (int slot = 0; slot < 2; ++slot) {
    const char* name = kSlotNames[slot];
    std::vector<std::uint8_t> bytes;
    const StorageResult r = storage_.read(name, bytes);
    if (r == StorageResult::not_found) continue;
    StoredTable candidate;
    std::string why;
    if (r != StorageResult::ok) {
      why = to_string(r);
    } else if (!decode_table(bytes, candidate)) {
      why = "payload does not decode";
    } else if (const core::TableError e = core::validate(candidate.table, motor_count_, limits_);
               e != core::TableError::none) {
      why = std::string("table rejected: ") + core::describe(e);
    }
    if (!why.empty()) {
      report += std::string(report.empty() ? "" : "; ") + name + " ignored (" + why + ")";
      continue;
    }
    if (!found || candidate.generation > out.generation) {
      out = candidate;
      newest_ = candidate;
      newest_slot_ = slot;
      newest_generation_ = candidate.generation;
      found = true;
    }
  }
  loaded_ = true;
  return found;
}

bool PolicyStore::current(StoredTable& out) const {
  if (newest_slot_ < 0) return false;
  out = newest_;
  return true;
}

StorageResult PolicyStore::save(const core::EndcapTable& table, const StoredIdentity& identity, std::string& error) {
  if (identity.policy_id.size() > kMaxStoredPolicyIdBytes) {
    error = "policy id longer than " + std::to_string(kMaxStoredPolicyIdBytes) + " bytes";
    return StorageResult::too_large;
  }
  if (const core::TableError e = core::validate(table, motor_count_, limits_); e != core::TableError::none) {
    error = std::string("table rejected: ") + core::describe(e);
    return StorageResult::corrupt;
  }
  if (!loaded_) {
    StoredTable ignored;
    std::string report;
    load(ignored, report);
  }
  // Never overwrite the newest good copy: if this write is lost, it is what remains.
  const int slot = newest_slot_ == 0 ? 1 : 0;
  const StoredTable stored{newest_generation_ + 1, table, identity};
  const std::vector<std::uint8_t> bytes = encode_table(stored);
  const StorageResult r = storage_.write(kSlotNames[slot], bytes);
  if (r != StorageResult::ok) {
    error = std::string(kSlotNames[slot]) + ": " + to_string(r);
    return r;
  }
  newest_slot_ = slot;
  newest_generation_ = stored.generation;
  newest_ = stored;
  return r;
}

}  // namespace tensegrity::fw::app
