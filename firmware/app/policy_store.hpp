// SPDX-License-Identifier: Apache-2.0
// Keeps the end cap's active table across reboots, together with the policy
// identity it was accepted under (id, version, checksum), as ONE record: a reboot
// finds the old table under the old identity or the new table under the new one,
// never a mix. Two slots ("table-a", "table-b") each hold a generation-numbered
// record; a save overwrites the slot that
// does not hold the newest good copy. FileStorage already writes atomically
// (temp, fsync, rename) and checks a CRC; the second slot also survives a file
// that rots later or a storage layer that misbehaves: whatever happens to one
// file, the previous table is still there. A slot that is corrupt, truncated or no
// longer valid for this end cap's limits is ignored (and reported).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/limits.hpp"
#include "core/table.hpp"
#include "firmware/hal/storage.hpp"

namespace tensegrity::fw::app {

// Under what name a table was accepted: the version check (a new table must be
// newer unless forced) and "already active" use it after a reboot.
struct StoredIdentity {
  std::string policy_id;  // empty: none known (a record written before identities were stored)
  std::uint32_t policy_version = 0;
  std::uint32_t checksum = 0;  // the policy table's checksum (docs/design/dds.md)
};
inline constexpr std::size_t kMaxStoredPolicyIdBytes = 64;

struct StoredTable {
  std::uint64_t generation = 0;
  core::EndcapTable table;
  StoredIdentity identity{};
};

// Binary payload, LE: "ETB2" | generation u64 | motor_count u32 | complexity u32 |
// period_s f64 | phase_offset_s f64 | motor_count*complexity f64 (motor-major) |
// policy_version u32 | checksum u32 | id length u32 (<= 64) | id bytes.
// "ETB1" records (the same without the identity) still decode, with no identity.
std::vector<std::uint8_t> encode_table(const StoredTable& stored);
bool decode_table(const std::vector<std::uint8_t>& bytes, StoredTable& out);

class PolicyStore {
 public:
  static constexpr const char* kSlotNames[2] = {"table-a", "table-b"};

  PolicyStore(Storage& storage, std::uint32_t motor_count, const core::MotorLimits& limits)
      : storage_(storage), motor_count_(motor_count), limits_(limits) {}

  // The newest good table; false when neither slot holds one. `report` gets one
  // line per slot that was ignored, for the log.
  bool load(StoredTable& out, std::string& report);
  // Validates, then writes the next generation into the older slot. Returns once
  // the record is durable (FileStorage: write, fsync, rename, fsync directory).
  StorageResult save(const core::EndcapTable& table, const StoredIdentity& identity, std::string& error);
  StorageResult save(const core::EndcapTable& table, std::string& error) { return save(table, {}, error); }
  // The newest good record after load() or save(); false when there is none.
  bool current(StoredTable& out) const;

 private:
  Storage& storage_;
  std::uint32_t motor_count_;
  core::MotorLimits limits_;
  StoredTable newest_{};
  std::uint64_t newest_generation_ = 0;
  int newest_slot_ = -1;
  bool loaded_ = false;
};

}  // namespace tensegrity::fw::app
