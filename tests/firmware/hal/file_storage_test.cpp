// SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

#include "firmware/hal/storage.hpp"

namespace tensegrity::fw {
namespace {

namespace fs = std::filesystem;

class FileStorageTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("tensegrity_storage_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static void write_raw(const fs::path& path, const std::vector<std::uint8_t>& bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  static std::vector<std::uint8_t> read_raw(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

  fs::path dir_;
};

const std::vector<std::uint8_t> kOld = {1, 2, 3, 4, 5};
const std::vector<std::uint8_t> kNew = {9, 8, 7, 6, 5, 4, 3, 2, 1, 0};

TEST_F(FileStorageTest, WriteThenReadRoundTrips) {
  FileStorage storage(dir_);
  ASSERT_EQ(storage.write("policy", kOld), StorageResult::ok);
  std::vector<std::uint8_t> got;
  ASSERT_EQ(storage.read("policy", got), StorageResult::ok);
  EXPECT_EQ(got, kOld);
  ASSERT_EQ(storage.write("policy", kNew), StorageResult::ok);
  ASSERT_EQ(storage.read("policy", got), StorageResult::ok);
  EXPECT_EQ(got, kNew);
  EXPECT_FALSE(fs::exists(storage.temp_path("policy")));
}

TEST_F(FileStorageTest, EmptyBlobIsAValidBlob) {
  FileStorage storage(dir_);
  ASSERT_EQ(storage.write("empty", {}), StorageResult::ok);
  std::vector<std::uint8_t> got = {42};
  ASSERT_EQ(storage.read("empty", got), StorageResult::ok);
  EXPECT_TRUE(got.empty());
}

TEST_F(FileStorageTest, MissingBlobIsNotFound) {
  FileStorage storage(dir_);
  std::vector<std::uint8_t> got;
  EXPECT_EQ(storage.read("absent", got), StorageResult::not_found);
}

TEST_F(FileStorageTest, RejectsNamesThatEscapeTheDirectory) {
  FileStorage storage(dir_);
  std::vector<std::uint8_t> got;
  for (const char* name : {"", "../x", "a/b", ".hidden", "with space"}) {
    EXPECT_EQ(storage.write(name, kOld), StorageResult::invalid_name) << name;
    EXPECT_EQ(storage.read(name, got), StorageResult::invalid_name) << name;
  }
}

// A write killed after it began the temp file but before the rename: the old
// blob must still read back, and the next write must succeed over the leftover.
TEST_F(FileStorageTest, WriteKilledBeforeRenameLeavesOldBlobIntact) {
  FileStorage storage(dir_);
  ASSERT_EQ(storage.write("policy", kOld), StorageResult::ok);
  std::vector<std::uint8_t> partial = read_raw(storage.blob_path("policy"));
  partial.resize(partial.size() / 2);
  write_raw(storage.temp_path("policy"), partial);

  std::vector<std::uint8_t> got;
  ASSERT_EQ(storage.read("policy", got), StorageResult::ok);
  EXPECT_EQ(got, kOld);

  ASSERT_EQ(storage.write("policy", kNew), StorageResult::ok);
  ASSERT_EQ(storage.read("policy", got), StorageResult::ok);
  EXPECT_EQ(got, kNew);
}

TEST_F(FileStorageTest, TruncatedBlobIsReportedCorrupt) {
  FileStorage storage(dir_);
  ASSERT_EQ(storage.write("policy", kNew), StorageResult::ok);
  std::vector<std::uint8_t> bytes = read_raw(storage.blob_path("policy"));
  for (const std::size_t keep : {std::size_t{0}, std::size_t{10}, bytes.size() - 1}) {
    write_raw(storage.blob_path("policy"), {bytes.begin(), bytes.begin() + static_cast<long>(keep)});
    std::vector<std::uint8_t> got;
    EXPECT_EQ(storage.read("policy", got), StorageResult::corrupt) << "kept " << keep;
  }
}

TEST_F(FileStorageTest, FlippedPayloadBitIsACrcMismatch) {
  FileStorage storage(dir_);
  ASSERT_EQ(storage.write("policy", kNew), StorageResult::ok);
  std::vector<std::uint8_t> bytes = read_raw(storage.blob_path("policy"));
  bytes.back() ^= 0x10;
  write_raw(storage.blob_path("policy"), bytes);
  std::vector<std::uint8_t> got = {7};
  EXPECT_EQ(storage.read("policy", got), StorageResult::corrupt);
  EXPECT_EQ(got, std::vector<std::uint8_t>{7}) << "output untouched on failure";
}

TEST_F(FileStorageTest, WrongMagicIsCorrupt) {
  FileStorage storage(dir_);
  ASSERT_EQ(storage.write("policy", kNew), StorageResult::ok);
  std::vector<std::uint8_t> bytes = read_raw(storage.blob_path("policy"));
  bytes[0] = 'X';
  write_raw(storage.blob_path("policy"), bytes);
  std::vector<std::uint8_t> got;
  EXPECT_EQ(storage.read("policy", got), StorageResult::corrupt);
}

TEST_F(FileStorageTest, WriteIntoMissingDirectoryIsAnIoError) {
  FileStorage storage(dir_ / "nope");
  EXPECT_EQ(storage.write("policy", kOld), StorageResult::io_error);
  EXPECT_NE(storage.last_errno(), 0);
}

// Two threads writing one blob (the node storing a table while the main thread
// stores one from --policy) must not share the temp file, and each reads the
// errno of its own failure.
TEST_F(FileStorageTest, ConcurrentWritersNeverLeaveABadBlobAndKeepTheirOwnErrno) {
  FileStorage storage(dir_);
  auto writer = [&storage](const std::vector<std::uint8_t>& data, int* bad) {
    for (int i = 0; i < 200; ++i) *bad += storage.write("policy", data) == StorageResult::ok ? 0 : 1;
  };
  int bad_a = 0, bad_b = 0;
  std::thread a(writer, kOld, &bad_a);
  std::thread b(writer, kNew, &bad_b);
  a.join();
  b.join();
  EXPECT_EQ(bad_a + bad_b, 0);
  std::vector<std::uint8_t> got;
  ASSERT_EQ(storage.read("policy", got), StorageResult::ok);
  EXPECT_TRUE(got == kOld || got == kNew);
  FileStorage missing(dir_ / "nope");
  EXPECT_EQ(missing.write("policy", kOld), StorageResult::io_error);
  EXPECT_NE(missing.last_errno(), 0);
  int other_thread_errno = -1;
  std::thread c([&] { other_thread_errno = missing.last_errno(); });
  c.join();
  EXPECT_EQ(other_thread_errno, 0) << "another thread's last error is its own (none)";
}

}  // namespace
}  // namespace tensegrity::fw
