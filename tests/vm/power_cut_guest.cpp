// SPDX-License-Identifier: Apache-2.0
// The end cap's policy store, cut off mid-write (tests/vm/power-cut.sh). Runs in a VM
// on an ext4 disk and writes through the end cap's own code: app::PolicyStore over
// FileStorage, as a DDS upload does (EndcapNode::commit). Record v holds table v
// under identity (powercut, v, checksum of table v) at generation v, so a record
// that says v must hold exactly that: anything else is a mix.
//
//   power_cut_guest DIR verify [--marks DEV]
//       reads the store as the end cap boots (PolicyStore::load) and each slot on its
//       own (FileStorage::read); prints "PC RECORD ..." and "PC SLOT ..." lines
//   power_cut_guest DIR write [--count N] [--break MODE] [--marks DEV]
//       saves record v+1 over the newest record v, N times (0: until the power goes),
//       with "PC BEGIN v" before and "PC ACK v" after each save returned
// MODE: none (default) | no-file-fsync | no-dir-fsync | no-fsync (negative controls).
#include <sys/stat.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "firmware/app/policy_store.hpp"
#include "firmware/hal/crc32.hpp"
#include "firmware/hal/storage.hpp"
#include "tests/vm/power_cut_marks.hpp"

namespace tensegrity::test::power_cut {
namespace {

using fw::FileStorage;
using fw::StorageResult;
using fw::app::PolicyStore;
using fw::app::StoredIdentity;
using fw::app::StoredTable;

// The largest record an end cap stores (4 motors x 16 values): 620 bytes with the
// storage header, one 4 KiB block of the disk.
constexpr std::uint32_t kMotors = core::kMaxMotorsPerEndcap;
constexpr std::uint32_t kComplexity = core::kMaxComplexity;
const core::MotorLimits kLimits{};

std::uint64_t splitmix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30U)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27U)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31U);
}

core::EndcapTable table_for(std::uint64_t version) {
  core::EndcapTable t;
  t.motor_count = kMotors;
  t.complexity = kComplexity;
  t.period_s = 1.0 + static_cast<double>(version % 64U) * 0.125;
  t.phase_offset_s = static_cast<double>(version % 5U) * 0.1;
  const double span = kLimits.max_rest_length_m - kLimits.min_rest_length_m;
  for (std::uint32_t m = 0; m < kMotors; ++m) {
    for (std::uint32_t j = 0; j < kComplexity; ++j) {
      const std::uint64_t h = splitmix(version * 1000U + m * kComplexity + j);
      t.rest_length_m[m][j] = kLimits.min_rest_length_m + span * static_cast<double>(h >> 11U) * 0x1.0p-53;
    }
  }
  return t;
}

StoredIdentity identity_for(std::uint64_t version) {
  const std::vector<std::uint8_t> bytes = fw::app::encode_table(StoredTable{0, table_for(version), {}});
  return {"powercut", static_cast<std::uint32_t>(version), fw::crc32(bytes)};
}

// Whether `s` is record v exactly: its generation, identity and every value.
bool is_whole(const StoredTable& s) {
  const std::uint64_t v = s.identity.policy_version;
  const StoredTable want{v, table_for(v), identity_for(v)};
  return s.generation == v && s.identity.policy_id == want.identity.policy_id &&
         s.identity.checksum == want.identity.checksum && fw::app::encode_table(s) == fw::app::encode_table(want);
}

std::string describe(const StoredTable& s) {
  return "version=" + std::to_string(s.identity.policy_version) + " generation=" + std::to_string(s.generation) +
         " whole=" + (is_whole(s) ? "1" : "0");
}

int verify(const std::filesystem::path& dir) {
  FileStorage storage(dir);
  for (const char* slot : PolicyStore::kSlotNames) {
    std::vector<std::uint8_t> bytes;
    const StorageResult r = storage.read(slot, bytes);
    std::string line = std::string("SLOT ") + slot + " ";
    StoredTable s;
    if (r == StorageResult::ok && fw::app::decode_table(bytes, s)) {
      line += "ok " + describe(s);
    } else if (r == StorageResult::ok) {
      line += "undecodable";
    } else {
      line += r == StorageResult::not_found ? "missing" : r == StorageResult::corrupt ? "corrupt" : "io_error";
    }
    struct stat st {};
    if (::stat(storage.temp_path(slot).c_str(), &st) == 0) line += " temp_bytes=" + std::to_string(st.st_size);
    say(line);
  }
  PolicyStore store(storage, kMotors, kLimits);
  StoredTable record;
  std::string report;
  const bool found = store.load(record, report);
  if (!report.empty()) say("LOADREPORT " + report);
  say(found ? "RECORD " + describe(record) : std::string("RECORD none"));
  return 0;
}

int write(const std::filesystem::path& dir, std::uint64_t count, Break how) {
  std::filesystem::create_directories(dir);
  FileStorage storage(dir);
  PolicyStore store(storage, kMotors, kLimits);
  StoredTable record;
  std::string report;
  const std::uint64_t first = store.load(record, report) ? record.identity.policy_version + 1U : 1U;
  for (std::uint64_t v = first; count == 0 || v < first + count; ++v) {
    set_current(v, how);
    mark("BEGIN", v);
    std::string error;
    if (store.save(table_for(v), identity_for(v), error) != StorageResult::ok) {
      say("SAVEFAILED " + std::to_string(v) + " " + error);
      return 1;
    }
    mark("ACK", v);
  }
  return 0;
}

int usage() {
  std::fputs("usage: power_cut_guest DIR verify|write [--count N] [--break MODE] [--marks DEV]\n", stderr);
  return 2;
}

int run(int argc, char** argv) {
  if (argc < 3) return usage();
  const std::filesystem::path dir = argv[1];
  const std::string mode = argv[2];
  std::uint64_t count = 0;
  Break how = Break::none;
  for (int i = 3; i + 1 < argc; i += 2) {
    const std::string opt = argv[i];
    if (opt == "--count") {
      count = std::strtoull(argv[i + 1], nullptr, 10);
    } else if (opt == "--break") {
      if (!parse_break(argv[i + 1], how)) return usage();
    } else if (opt == "--marks") {
      open_marks(argv[i + 1]);
    } else {
      return usage();
    }
  }
  if ((argc - 3) % 2 != 0) return usage();
  if (mode == "verify") return verify(dir);
  if (mode == "write") return write(dir, count, how);
  return usage();
}

}  // namespace
}  // namespace tensegrity::test::power_cut

int main(int argc, char** argv) { return tensegrity::test::power_cut::run(argc, argv); }
