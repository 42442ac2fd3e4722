// SPDX-License-Identifier: Apache-2.0
// Persistent named blobs (policy tables, calibration). A write replaces the whole
// blob atomically: after a crash or power cut a reader sees the old blob or the
// new one, never a mix.
#pragma once

#include <cstdint>
#include <filesystem>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tensegrity::fw {

enum class StorageResult : std::uint8_t {
  ok,
  not_found,
  invalid_name,  // names are [A-Za-z0-9_.-], 1..64 chars, not starting with '.'
  too_large,
  corrupt,  // header, length or CRC does not match: the blob is not trusted
  io_error,
};

const char* to_string(StorageResult result);

class Storage {
 public:
  virtual ~Storage() = default;
  virtual StorageResult read(std::string_view name, std::vector<std::uint8_t>& out) = 0;
  virtual StorageResult write(std::string_view name, std::span<const std::uint8_t> data) = 0;
};

bool is_valid_blob_name(std::string_view name);

// One file per blob in `directory`. File layout (little-endian):
//   "TBLB" | version u32 (1) | payload length u32 | crc32(payload) u32 | payload
// Writing goes to ".NAME.tmp" in the same directory, fsyncs it, renames it over
// NAME and fsyncs the directory, so the rename itself is durable.
class FileStorage final : public Storage {
 public:
  static constexpr std::size_t kMaxBlobBytes = 64U * 1024U * 1024U;

  explicit FileStorage(std::filesystem::path directory);
  StorageResult read(std::string_view name, std::vector<std::uint8_t>& out) override;
  StorageResult write(std::string_view name, std::span<const std::uint8_t> data) override;

  const std::filesystem::path& directory() const { return directory_; }
  std::filesystem::path blob_path(std::string_view name) const;
  std::filesystem::path temp_path(std::string_view name) const;
  // errno of the calling thread's last io_error, for its log line. Per thread:
  // the node persists while the main thread may read, and a value shared by both
  // would be a data race and could name the other thread's error.
  static int last_errno();

 private:
  std::filesystem::path directory_;
  // Two writers of one blob would share its temp file: writes are serialised.
  std::mutex write_mutex_;
};

}  // namespace tensegrity::fw
