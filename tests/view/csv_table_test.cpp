// SPDX-License-Identifier: Apache-2.0
#include "view/csv_table.hpp"

#include <gtest/gtest.h>

#include <fstream>

namespace tensegrity::view {
namespace {

std::filesystem::path write(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::path(testing::TempDir()) / name;
  std::ofstream(path) << text;
  return path;
}

struct Read {
  CsvHeader header;
  std::vector<std::vector<double>> rows;
  std::vector<std::size_t> lines;
  CsvReadResult result;
};

Read read(const std::filesystem::path& path) {
  Read r;
  r.result = read_numeric_csv(path, r.header, [&](std::size_t line, std::span<const double> row) {
    r.lines.push_back(line);
    r.rows.emplace_back(row.begin(), row.end());
  });
  return r;
}

std::string error_of(const std::filesystem::path& path) {
  try {
    read(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(CsvTable, ReadsNumbersAndNamesTheColumns) {
  const Read r = read(write("good.csv", "time_s,a,b\n0,1.5,-2\r\n0.1,3e2,4\n\n"));
  ASSERT_EQ(r.rows.size(), 2U);
  EXPECT_EQ(r.header.find("b"), 2);
  EXPECT_EQ(r.header.find("c"), -1);
  EXPECT_DOUBLE_EQ(r.rows[1][1], 300.0);
  EXPECT_DOUBLE_EQ(r.rows[0][2], -2.0);
  EXPECT_EQ(r.lines, (std::vector<std::size_t>{2, 3}));
}

TEST(CsvTable, ABadFieldNamesFileLineColumnAndName) {
  const std::string e = error_of(write("bad_field.csv", "time_s,a,b\n0,1,2\n0.1,x1,2\n0.2,1,2\n"));
  EXPECT_NE(e.find("bad_field.csv:3:2 (a): 'x1' is not a finite number"), std::string::npos) << e;
}

TEST(CsvTable, NotFiniteIsRefused) {
  const std::string e = error_of(write("nan.csv", "time_s,a\n0,nan\n"));
  EXPECT_NE(e.find("nan.csv:2:2 (a)"), std::string::npos) << e;
}

TEST(CsvTable, AWrongFieldCountIsRefused) {
  EXPECT_NE(error_of(write("short.csv", "time_s,a,b\n0,1\n0.1,1,2\n")).find("short.csv:2: 2 fields, the header has 3"),
            std::string::npos);
  EXPECT_NE(error_of(write("long.csv", "time_s,a\n0,1,2\n")).find("long.csv:2: 3 fields, the header has 2"),
            std::string::npos);
}

TEST(CsvTable, ACutLastLineIsDroppedWithAWarningAndTheRestKept) {
  const Read r = read(write("cut.csv", "time_s,a,b\n0,1,2\n0.1,1,2\n0.2,1"));
  EXPECT_EQ(r.rows.size(), 2U);
  ASSERT_EQ(r.result.warnings.size(), 1U);
  EXPECT_NE(r.result.warnings[0].find("cut.csv:4"), std::string::npos);
}

TEST(CsvTable, ABadLineBeforeTheLastIsAnError) {
  EXPECT_NE(error_of(write("mid.csv", "time_s,a\n0,1\n0.1,\n0.2,1\n")).find("mid.csv:3:2 (a)"), std::string::npos);
}

TEST(CsvTable, TheHeaderMustStartWithTime) {
  EXPECT_NE(error_of(write("notime.csv", "t,a\n0,1\n")).find("notime.csv:1:1"), std::string::npos);
  EXPECT_NE(error_of(write("empty.csv", "")).find("empty file"), std::string::npos);
  EXPECT_NE(error_of(write("header.csv", "time_s,a\n")).find("no data rows"), std::string::npos);
  EXPECT_NE(error_of(std::filesystem::path(testing::TempDir()) / "absent.csv").find("cannot open"), std::string::npos);
}

}  // namespace
}  // namespace tensegrity::view
