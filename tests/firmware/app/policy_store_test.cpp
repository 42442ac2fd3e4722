// SPDX-License-Identifier: Apache-2.0
// A table write that dies midway, a file that rots, a stale temp file: the end cap
// still boots with the last good table.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "firmware/app/policy_store.hpp"
#include "firmware/hal/storage.hpp"

namespace tensegrity::fw::app {
namespace {

namespace fs = std::filesystem;

core::EndcapTable table_with(double first_m) {
  core::EndcapTable t;
  t.motor_count = 2;
  t.complexity = 3;
  t.period_s = 1.5;
  for (std::uint32_t m = 0; m < 2; ++m) {
    for (std::uint32_t j = 0; j < 3; ++j) t.rest_length_m[m][j] = first_m + 0.01 * j + 0.1 * m;
  }
  return t;
}

class PolicyStoreTest : public ::testing::Test {
 protected:
  static fs::path make_dir() {
    const fs::path d = fs::temp_directory_path() / ("endcap_store_" + std::to_string(std::random_device{}()));
    fs::create_directories(d);
    return d;
  }
  PolicyStoreTest() : dir(make_dir()), storage(dir) {}
  void TearDown() override { fs::remove_all(dir); }
  PolicyStore store() { return PolicyStore(storage, 2, core::MotorLimits{}); }
  // The slot file the newest save went to.
  fs::path newest_file() {
    const fs::path a = storage.blob_path("table-a");
    const fs::path b = storage.blob_path("table-b");
    if (!fs::exists(b)) return a;
    return fs::last_write_time(a) > fs::last_write_time(b) ? a : b;
  }
  double loaded_first_m() {
    StoredTable s;
    std::string report;
    PolicyStore fresh = store();  // a reboot: nothing cached
    if (!fresh.load(s, report)) return -1.0;
    last_report = report;
    return s.table.rest_length_m[0][0];
  }

  fs::path dir;
  FileStorage storage;
  std::string last_report;
};

TEST_F(PolicyStoreTest, RoundTripsAndAlternatesSlots) {
  PolicyStore s = store();
  std::string error;
  ASSERT_EQ(s.save(table_with(0.7), error), StorageResult::ok) << error;
  ASSERT_EQ(s.save(table_with(0.8), error), StorageResult::ok) << error;
  EXPECT_TRUE(fs::exists(storage.blob_path("table-a")));
  EXPECT_TRUE(fs::exists(storage.blob_path("table-b")));
  EXPECT_DOUBLE_EQ(loaded_first_m(), 0.8);
  ASSERT_EQ(s.save(table_with(0.9), error), StorageResult::ok);
  EXPECT_DOUBLE_EQ(loaded_first_m(), 0.9);
}

TEST_F(PolicyStoreTest, TruncatedNewestFileLeavesThePreviousTable) {
  PolicyStore s = store();
  std::string error;
  ASSERT_EQ(s.save(table_with(0.7), error), StorageResult::ok);
  ASSERT_EQ(s.save(table_with(0.8), error), StorageResult::ok);
  const fs::path newest = storage.blob_path("table-b");
  fs::resize_file(newest, fs::file_size(newest) / 2);  // power cut in a storage without atomic rename
  EXPECT_DOUBLE_EQ(loaded_first_m(), 0.7);
  EXPECT_NE(last_report.find("table-b ignored"), std::string::npos) << last_report;
}

TEST_F(PolicyStoreTest, GarbageAndCrcMismatchAreIgnored) {
  PolicyStore s = store();
  std::string error;
  ASSERT_EQ(s.save(table_with(0.7), error), StorageResult::ok);
  ASSERT_EQ(s.save(table_with(0.8), error), StorageResult::ok);
  {
    // Flip one payload byte: the header is intact, the CRC no longer matches.
    std::fstream f(storage.blob_path("table-b"), std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(20);
    char c = 0;
    f.read(&c, 1);
    f.seekp(20);
    c = static_cast<char>(c ^ 0x5A);
    f.write(&c, 1);
  }
  EXPECT_DOUBLE_EQ(loaded_first_m(), 0.7);
  EXPECT_NE(last_report.find("corrupt"), std::string::npos) << last_report;

  std::ofstream(storage.blob_path("table-b"), std::ios::binary | std::ios::trunc) << "not a table at all";
  EXPECT_DOUBLE_EQ(loaded_first_m(), 0.7);
}

TEST_F(PolicyStoreTest, StaleTempFileFromAKilledWriteIsIgnored) {
  PolicyStore s = store();
  std::string error;
  ASSERT_EQ(s.save(table_with(0.7), error), StorageResult::ok);
  // A write killed before its rename leaves only the temp file behind.
  std::ofstream(storage.temp_path("table-b"), std::ios::binary) << "TBLB half of a blob";
  EXPECT_DOUBLE_EQ(loaded_first_m(), 0.7);
  // The next save goes through despite the leftover.
  PolicyStore again = store();
  StoredTable ignored;
  std::string report;
  again.load(ignored, report);
  ASSERT_EQ(again.save(table_with(0.8), error), StorageResult::ok) << error;
  EXPECT_DOUBLE_EQ(loaded_first_m(), 0.8);
}

TEST_F(PolicyStoreTest, SaveNeverOverwritesTheNewestGoodCopy) {
  PolicyStore s = store();
  std::string error;
  ASSERT_EQ(s.save(table_with(0.7), error), StorageResult::ok);  // generation 1 -> a
  ASSERT_EQ(s.save(table_with(0.8), error), StorageResult::ok);  // generation 2 -> b
  fs::resize_file(storage.blob_path("table-b"), 3);              // b lost
  PolicyStore after_reboot = store();
  StoredTable stored;
  std::string report;
  ASSERT_TRUE(after_reboot.load(stored, report));
  EXPECT_DOUBLE_EQ(stored.table.rest_length_m[0][0], 0.7);
  ASSERT_EQ(after_reboot.save(table_with(0.9), error), StorageResult::ok);
  fs::resize_file(storage.blob_path("table-b"), 3);  // and that write lost too
  EXPECT_DOUBLE_EQ(loaded_first_m(), 0.7) << "slot a (the good copy) was not the one written";
}

TEST_F(PolicyStoreTest, InvalidTableIsNotStored) {
  PolicyStore s = store();
  std::string error;
  core::EndcapTable bad = table_with(0.7);
  bad.rest_length_m[1][2] = 5.0;
  EXPECT_NE(s.save(bad, error), StorageResult::ok);
  EXPECT_NE(error.find("rejected"), std::string::npos);
  EXPECT_DOUBLE_EQ(loaded_first_m(), -1.0);
}

TEST_F(PolicyStoreTest, TableAndIdentityAreOneRecord) {
  PolicyStore s = store();
  std::string error;
  ASSERT_EQ(s.save(table_with(0.7), StoredIdentity{"gait", 4, 0xABCD}, error), StorageResult::ok) << error;
  ASSERT_EQ(s.save(table_with(0.8), StoredIdentity{"gait", 5, 0x1234}, error), StorageResult::ok) << error;
  StoredTable current;
  ASSERT_TRUE(s.current(current));
  EXPECT_EQ(current.identity.policy_version, 5U);
  StoredTable loaded;
  std::string report;
  PolicyStore rebooted = store();
  ASSERT_TRUE(rebooted.load(loaded, report));
  EXPECT_DOUBLE_EQ(loaded.table.rest_length_m[0][0], 0.8);
  EXPECT_EQ(loaded.identity.policy_id, "gait");
  EXPECT_EQ(loaded.identity.policy_version, 5U);
  EXPECT_EQ(loaded.identity.checksum, 0x1234U);
  // The newest record lost: the previous table comes back with its own identity.
  fs::resize_file(newest_file(), 20);
  PolicyStore again = store();
  ASSERT_TRUE(again.load(loaded, report));
  EXPECT_DOUBLE_EQ(loaded.table.rest_length_m[0][0], 0.7);
  EXPECT_EQ(loaded.identity.policy_version, 4U);
  EXPECT_EQ(loaded.identity.checksum, 0xABCDU);
}

TEST_F(PolicyStoreTest, AnOverlongPolicyIdIsRefusedNotTruncated) {
  PolicyStore s = store();
  std::string error;
  EXPECT_NE(s.save(table_with(0.7), StoredIdentity{std::string(65, 'x'), 1, 1}, error), StorageResult::ok);
  EXPECT_FALSE(error.empty());
}

TEST(PolicyStoreCodec, VersionOneRecordsDecodeWithoutAnIdentity) {
  StoredTable s{3, table_with(0.7), {}};
  std::vector<std::uint8_t> bytes = encode_table(s);
  // ETB1: the same record without the identity's 12 bytes (version, checksum, id length 0).
  bytes[3] = '1';
  bytes.resize(bytes.size() - 12);
  StoredTable out;
  ASSERT_TRUE(decode_table(bytes, out));
  EXPECT_TRUE(out.identity.policy_id.empty());
  EXPECT_DOUBLE_EQ(out.table.rest_length_m[1][2], 0.7 + 0.02 + 0.1);
}

TEST(PolicyStoreCodec, DecodeRejectsTrailingAndShortBytes) {
  StoredTable s{3, table_with(0.7), {"gait", 2, 7}};
  std::vector<std::uint8_t> bytes = encode_table(s);
  StoredTable out;
  ASSERT_TRUE(decode_table(bytes, out));
  EXPECT_EQ(out.generation, 3U);
  bytes.push_back(0);
  EXPECT_FALSE(decode_table(bytes, out));
  bytes.resize(bytes.size() - 10);
  EXPECT_FALSE(decode_table(bytes, out));
}

}  // namespace
}  // namespace tensegrity::fw::app
