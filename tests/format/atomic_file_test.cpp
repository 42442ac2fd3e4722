// SPDX-License-Identifier: Apache-2.0
// The one atomic write: the target holds the old content or the new, never a mix,
// and a failed write leaves no temporary behind.
#include "format/atomic_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

namespace tensegrity::format {
namespace {

namespace fs = std::filesystem;

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class AtomicFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("atomic-file-test-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  fs::path dir;
};

TEST_F(AtomicFile, CreatesAndReplacesInBothDurabilities) {
  const fs::path target = dir / "policy.json";
  write_file_atomic(target, "first\n");
  EXPECT_EQ(read(target), "first\n");
  write_file_atomic(target, "second, longer than the first\n", Durability::atomic_only);
  EXPECT_EQ(read(target), "second, longer than the first\n");
  write_file_atomic(target, "");
  EXPECT_EQ(read(target), "");
  EXPECT_FALSE(fs::exists(dir / "policy.json.tmp"));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

TEST_F(AtomicFile, AFailedRenameKeepsTheOldTargetAndRemovesTheTemporary) {
  // A non-empty directory cannot be renamed over: the write fails at its last step.
  const fs::path target = dir / "busy";
  fs::create_directories(target / "inside");
  try {
    write_file_atomic(target, "new");
    FAIL() << "renaming over a non-empty directory succeeded";
  } catch (const std::system_error& e) {
    EXPECT_NE(std::string(e.what()).find("busy"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_directory(target / "inside"));
  EXPECT_FALSE(fs::exists(dir / "busy.tmp"));
}

TEST_F(AtomicFile, AMissingDirectoryIsNamed) {
  const fs::path target = dir / "no-such-dir" / "curve.csv";
  try {
    write_file_atomic(target, "x");
    FAIL() << "wrote into a directory that does not exist";
  } catch (const std::system_error& e) {
    EXPECT_NE(std::string(e.what()).find("no-such-dir"), std::string::npos) << e.what();
    EXPECT_EQ(e.code(), std::errc::no_such_file_or_directory);
  }
}

}  // namespace
}  // namespace tensegrity::format
