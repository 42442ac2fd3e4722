// SPDX-License-Identifier: Apache-2.0
// Keeps the end cap's active table across reboots. Two slots ("table-a",
// "table-b") each hold a generation-numbered copy; a save overwrites the slot that
// does not hold the newest good copy. FileStorage already writes atomically
// (temp, fsync, rename) and checks a CRC; the second slot also survives a file
// that rots later or a storage layer that misbehaves: whatever happens to one
// file, the previous table is still there. A slot that is corrupt, truncated or no
// longer valid for this end cap's limits is ignored (and reported).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "firmware/core/limits.hpp"
#include "firmware/core/table.hpp"
#include "firmware/hal/storage.hpp"

namespace tensegrity::fw::app {

struct StoredTable {
  std::uint64_t generation = 0;
  core::EndcapTable table;
};

// Binary payload: "ETB1" | generation u64 | motor_count u32 | complexity u32 |
// period_s f64 | phase_offset_s f64 | motor_count*complexity f64 (motor-major), LE.
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
  // Validates, then writes the next generation into the older slot.
  StorageResult save(const core::EndcapTable& table, std::string& error);

 private:
  Storage& storage_;
  std::uint32_t motor_count_;
  core::MotorLimits limits_;
  std::uint64_t newest_generation_ = 0;
  int newest_slot_ = -1;
  bool loaded_ = false;
};

}  // namespace tensegrity::fw::app
