// SPDX-License-Identifier: Apache-2.0
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "firmware/hal/crc32.hpp"
#include "firmware/hal/storage.hpp"

namespace tensegrity::fw {
namespace {

constexpr std::array<std::uint8_t, 4> kMagic = {'T', 'B', 'L', 'B'};
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kHeaderBytes = 16;

void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

std::uint32_t get_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

// Closes on every path so an early return cannot leak the descriptor.
class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  int get() const { return fd_; }
  int release_close() {
    const int rc = ::close(fd_);
    fd_ = -1;
    return rc;
  }

 private:
  int fd_;
};

bool write_all(int fd, const std::uint8_t* p, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    p += w;
    n -= static_cast<std::size_t>(w);
  }
  return true;
}

thread_local int t_last_errno = 0;

}  // namespace

int FileStorage::last_errno() { return t_last_errno; }

const char* to_string(StorageResult result) {
  switch (result) {
    case StorageResult::ok: return "ok";
    case StorageResult::not_found: return "not found";
    case StorageResult::invalid_name: return "invalid blob name";
    case StorageResult::too_large: return "blob too large";
    case StorageResult::corrupt: return "blob corrupt (header, length or CRC mismatch)";
    case StorageResult::io_error: return "I/O error";
  }
  return "unknown";
}

bool is_valid_blob_name(std::string_view name) {
  if (name.empty() || name.size() > 64 || name.front() == '.') return false;
  for (const char c : name) {
    const bool ok =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '.';
    if (!ok) return false;
  }
  return true;
}

FileStorage::FileStorage(std::filesystem::path directory) : directory_(std::move(directory)) {}

std::filesystem::path FileStorage::blob_path(std::string_view name) const { return directory_ / std::string(name); }

std::filesystem::path FileStorage::temp_path(std::string_view name) const {
  return directory_ / ("." + std::string(name) + ".tmp");
}

StorageResult FileStorage::read(std::string_view name, std::vector<std::uint8_t>& out) {
  if (!is_valid_blob_name(name)) return StorageResult::invalid_name;
  Fd fd(::open(blob_path(name).c_str(), O_RDONLY | O_CLOEXEC));
  if (fd.get() < 0) {
    t_last_errno = errno;
    return errno == ENOENT ? StorageResult::not_found : StorageResult::io_error;
  }
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) {
    t_last_errno = errno;
    return StorageResult::io_error;
  }
  const auto file_bytes = static_cast<std::size_t>(st.st_size);
  if (file_bytes < kHeaderBytes) return StorageResult::corrupt;
  if (file_bytes - kHeaderBytes > kMaxBlobBytes) return StorageResult::corrupt;

  std::vector<std::uint8_t> bytes(file_bytes);
  std::size_t got = 0;
  while (got < file_bytes) {
    const ssize_t r = ::read(fd.get(), bytes.data() + got, file_bytes - got);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) {
      t_last_errno = errno;
      return StorageResult::io_error;
    }
    if (r == 0) return StorageResult::corrupt;  // shrank under us
    got += static_cast<std::size_t>(r);
  }
  if (std::memcmp(bytes.data(), kMagic.data(), kMagic.size()) != 0) return StorageResult::corrupt;
  if (get_u32(bytes.data() + 4) != kVersion) return StorageResult::corrupt;
  const std::uint32_t length = get_u32(bytes.data() + 8);
  const std::uint32_t crc = get_u32(bytes.data() + 12);
  if (length != file_bytes - kHeaderBytes) return StorageResult::corrupt;
  const std::span<const std::uint8_t> payload(bytes.data() + kHeaderBytes, length);
  if (crc32(payload) != crc) return StorageResult::corrupt;
  out.assign(payload.begin(), payload.end());
  return StorageResult::ok;
}

StorageResult FileStorage::write(std::string_view name, std::span<const std::uint8_t> data) {
  if (!is_valid_blob_name(name)) return StorageResult::invalid_name;
  if (data.size() > kMaxBlobBytes) return StorageResult::too_large;

  std::array<std::uint8_t, kHeaderBytes> header{};
  std::memcpy(header.data(), kMagic.data(), kMagic.size());
  put_u32(header.data() + 4, kVersion);
  put_u32(header.data() + 8, static_cast<std::uint32_t>(data.size()));
  put_u32(header.data() + 12, crc32(data));

  const std::lock_guard lock(write_mutex_);
  const std::filesystem::path tmp = temp_path(name);
  // O_TRUNC: a temp file left by an interrupted earlier write is simply reused.
  Fd fd(::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644));
  if (fd.get() < 0) {
    t_last_errno = errno;
    return StorageResult::io_error;
  }
  const bool written = write_all(fd.get(), header.data(), header.size()) &&
                       write_all(fd.get(), data.data(), data.size()) && ::fsync(fd.get()) == 0;
  if (!written || fd.release_close() != 0) {
    t_last_errno = errno;
    ::unlink(tmp.c_str());
    return StorageResult::io_error;
  }
  if (::rename(tmp.c_str(), blob_path(name).c_str()) != 0) {
    t_last_errno = errno;
    ::unlink(tmp.c_str());
    return StorageResult::io_error;
  }
  // Without this the rename may be lost on power failure even though the data was synced.
  Fd dir(::open(directory_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (dir.get() < 0 || ::fsync(dir.get()) != 0) {
    t_last_errno = errno;
    return StorageResult::io_error;
  }
  return StorageResult::ok;
}

}  // namespace tensegrity::fw
