// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: the end cap's stored policy table as it reads it back at boot.
// The first byte picks the layer: a whole blob file (FileStorage's "TBLB" frame
// with its CRC, then the payload), or the two slots' payloads behind a good frame
// (the CRC would stop almost every mutation before the payload decoder), read by
// PolicyStore::load, which decodes and validates them.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "firmware/app/policy_store.hpp"
#include "firmware/hal/storage.hpp"

namespace app = tensegrity::fw::app;
namespace core = tensegrity::core;
using tensegrity::fw::Storage;
using tensegrity::fw::StorageResult;

namespace {

class MemoryStorage final : public Storage {
 public:
  StorageResult read(std::string_view name, std::vector<std::uint8_t>& out) override {
    const auto it = blobs.find(std::string(name));
    if (it == blobs.end()) return StorageResult::not_found;
    out = it->second;
    return StorageResult::ok;
  }
  StorageResult write(std::string_view name, std::span<const std::uint8_t> data) override {
    blobs[std::string(name)].assign(data.begin(), data.end());
    return StorageResult::ok;
  }
  std::map<std::string, std::vector<std::uint8_t>> blobs;
};

// Whatever load() takes must be a table the loop may run, and must survive its
// own encoding unchanged (the next save writes it back).
void check_loaded(Storage& storage) {
  const core::MotorLimits limits;
  app::PolicyStore store(storage, 2, limits);
  app::StoredTable table;
  std::string report;
  if (!store.load(table, report)) return;
  if (core::validate(table.table, 2, limits) != core::TableError::none) std::abort();
  app::StoredTable again;
  if (!app::decode_table(app::encode_table(table), again)) std::abort();
  if (again.generation != table.generation || again.identity.policy_id != table.identity.policy_id ||
      again.identity.checksum != table.identity.checksum || again.table.complexity != table.table.complexity) {
    std::abort();
  }
}

const std::filesystem::path& scratch_dir() {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path base = std::filesystem::exists("/dev/shm") ? "/dev/shm" : "/tmp";
    std::filesystem::path d = base / ("tensegrity-fuzz-store-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t mode = data[0];
  const std::uint8_t* rest = data + 1;
  const std::size_t n = size - 1;
  if ((mode & 3U) == 0) {
    // A whole file as found on the end cap's disk.
    tensegrity::fw::FileStorage files(scratch_dir());
    std::ofstream(files.blob_path("table-a"), std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(rest), static_cast<std::streamsize>(n));
    std::vector<std::uint8_t> payload;
    if (files.read("table-a", payload) == StorageResult::ok) {
      MemoryStorage memory;
      memory.blobs["table-a"] = payload;
      check_loaded(memory);
    }
    return 0;
  }
  // Two payloads: slot a up to the split the second byte names, slot b after it.
  MemoryStorage memory;
  const std::size_t split = n == 0 ? 0 : (std::size_t{rest[0]} * 4) % (n + 1);
  if (n > 0) memory.blobs["table-a"].assign(rest + 1, rest + (split > 1 ? split : 1));
  if ((mode & 4U) != 0 && split < n) memory.blobs["table-b"].assign(rest + split, rest + n);
  check_loaded(memory);
  return 0;
}
