// SPDX-License-Identifier: Apache-2.0
// `tensegrity status --once` honours --endcaps: it shows the expected end caps
// only, and exits 1 naming the ones that sent no heartbeat. The formatting on its
// own, then the program against three end-cap nodes (comms_test_node).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <regex>

#include <nlohmann/json.hpp>

#include "ground/status.hpp"
#include "tests/ground/subprocess.hpp"

namespace tensegrity::ground {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using test::Subprocess;

constexpr int kDomain = 159;  // unique per DDS test: ctest runs tests in parallel

std::array<EndcapStatus, kEndcapCount> seen(std::initializer_list<int> endcaps) {
  std::array<EndcapStatus, kEndcapCount> s{};
  for (const int e : endcaps) s[static_cast<std::size_t>(e)].seen = true;
  return s;
}

std::vector<int> rows(const std::string& table) {
  std::vector<int> out;
  const std::regex row(R"(^\s+(\d+)\s)", std::regex::multiline);
  for (std::sregex_iterator it(table.begin(), table.end(), row), end; it != end; ++it)
    out.push_back(std::stoi((*it)[1]));
  return out;
}

TEST(StatusFormat, ShowsOnlyTheExpectedEndcapsAndNamesTheMissingOnes) {
  const auto status = seen({0, 1, 2});
  const std::uint16_t expected = 0b1011;  // 0, 1, 3
  EXPECT_EQ(missing_endcaps(status, expected), std::vector<int>{3});
  EXPECT_TRUE(missing_endcaps(status, 0b111).empty());
  EXPECT_EQ(missing_endcaps(status, kAllEndcaps).size(), 9U);

  const std::string table = format_status_table(status, 0, expected);
  EXPECT_EQ(rows(table), (std::vector<int>{0, 1, 3})) << table;
  EXPECT_NE(table.find("(no heartbeat)"), std::string::npos);

  const json j = json::parse(format_status_json(status, 0, expected));
  ASSERT_EQ(j["endcaps"].size(), 3U);
  EXPECT_EQ(j["endcaps"][2]["endcap"], 3);
  EXPECT_EQ(j["endcaps"][2]["seen"], false);
  EXPECT_EQ(j["missing"], json::array({3}));
  // All twelve by default, as before.
  EXPECT_EQ(json::parse(format_status_json(status, 0))["endcaps"].size(), 12U);
}

// The table's row of end cap `e` (rows start with the id right-aligned in 6 columns).
std::string table_row(const std::string& table, int e) {
  const std::size_t at = table.find("\n     " + std::to_string(e) + " ");
  return table.substr(at + 1, table.find('\n', at + 1) - at - 1);
}

TEST(StatusFormat, AnEndcapNotHeardLatelyIsMarkedSilentNotShownAsItWas) {
  auto status = seen({0, 1});
  const std::int64_t now_ns = 10'000'000'000;
  status[0].heartbeat_host_ns = now_ns - 500'000'000;    // 0.5 s ago: heard
  status[1].heartbeat_host_ns = now_ns - 2'500'000'000;  // 2.5 s ago: past Station::kHeardFreshS
  EXPECT_EQ(silent_endcaps(status, now_ns, 0b11), std::vector<int>{1});
  EXPECT_TRUE(silent_endcaps(status, now_ns, 0b01).empty()) << "only the expected ones";
  const std::string table = format_status_table(status, now_ns, 0b11);
  const auto row = [&table](int e) { return table_row(table, e); };
  EXPECT_EQ(row(0).find("SILENT"), std::string::npos) << table;
  EXPECT_NE(row(1).find("SILENT"), std::string::npos) << table;
  const json j = json::parse(format_status_json(status, now_ns, 0b11));
  EXPECT_EQ(j["endcaps"][0]["heard"], true);
  EXPECT_EQ(j["endcaps"][1]["heard"], false);
  EXPECT_EQ(j["silent"], json::array({1}));
  EXPECT_EQ(j["missing"], json::array());
}

class StatusOnce : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("status_once_" + std::to_string(std::random_device{}()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    nodes_.reset();
    fs::remove_all(dir_);
  }
  int status(std::vector<std::string> args, std::string& out, std::string& err) {
    args.insert(args.begin(), {TENSEGRITY_CLI, "status", "--once", "--domain", std::to_string(kDomain), "--insecure"});
    Subprocess cli(args, dir_ / "cli.out", dir_ / "cli.err");
    const int rc = cli.wait_exit(std::chrono::seconds(60));
    std::ifstream o(dir_ / "cli.out"), e(dir_ / "cli.err");
    out.assign(std::istreambuf_iterator<char>(o), {});
    err.assign(std::istreambuf_iterator<char>(e), {});
    return rc;
  }

  fs::path dir_;
  std::unique_ptr<Subprocess> nodes_;
};

TEST_F(StatusOnce, HonoursEndcaps) {
  // End caps 0, 1 and 2 only.
  nodes_ = std::make_unique<Subprocess>(
      std::vector<std::string>{COMMS_TEST_NODE, "--domain", std::to_string(kDomain), "--endcaps", "0-2", "--quiet"},
      dir_ / "nodes.out", dir_ / "nodes.err");
  ASSERT_TRUE(nodes_->wait_for_output("READY", std::chrono::seconds(20)));
  std::string out, err;

  // Exactly the three that run: every one shown, nothing else, exit 0.
  ASSERT_EQ(status({"--endcaps", "0-2", "--json", "--timeout", "15"}, out, err), 0) << out << err;
  json j = json::parse(out);
  ASSERT_EQ(j["endcaps"].size(), 3U) << out;
  for (int e = 0; e < 3; ++e) {
    EXPECT_EQ(j["endcaps"][static_cast<std::size_t>(e)]["endcap"], e);
    EXPECT_EQ(j["endcaps"][static_cast<std::size_t>(e)]["seen"], true);
  }
  EXPECT_TRUE(j["missing"].empty());

  // A subset: only those rows.
  ASSERT_EQ(status({"--endcaps", "0,2", "--timeout", "15"}, out, err), 0) << out << err;
  EXPECT_EQ(rows(out), (std::vector<int>{0, 2})) << out;

  // One expected end cap is not there: the snapshot still prints, marked, and the
  // exit code and message say which one. (The wait runs to its end here: long
  // enough for a new participant to hear the three others on a loaded machine.)
  ASSERT_EQ(status({"--endcaps", "0-3", "--json", "--timeout", "4"}, out, err), 1) << out << err;
  j = json::parse(out);
  ASSERT_EQ(j["endcaps"].size(), 4U);
  EXPECT_EQ(j["endcaps"][3]["seen"], false);
  EXPECT_EQ(j["missing"], json::array({3}));
  EXPECT_NE(err.find("within 4.0 s from end cap(s) 3 of --endcaps 0-3"), std::string::npos) << err;

  // A set that is not one: refused before anything is sent.
  EXPECT_EQ(status({"--endcaps", "0-12"}, out, err), 2) << err;
  EXPECT_NE(err.find("--endcaps"), std::string::npos) << err;
}

// Heard is not reached: an end cap whose readers this station's writers have not
// matched is marked, since an estop from here would go to nobody.
TEST(StatusFormat, AnEndcapHeardButNotReachedIsMarked) {
  auto status = seen({0, 1});
  const std::int64_t now_ns = 10'000'000'000;
  status[0].heartbeat_host_ns = status[1].heartbeat_host_ns = now_ns;
  status[0].reached = true;
  const std::string table = format_status_table(status, now_ns, 0b11);
  const auto row = [&table](int e) { return table_row(table, e); };
  EXPECT_EQ(row(0).find("UNREACHED"), std::string::npos) << table;
  EXPECT_NE(row(1).find("UNREACHED"), std::string::npos) << table;
  const json j = json::parse(format_status_json(status, now_ns, 0b11));
  EXPECT_EQ(j["endcaps"][0]["reached"], true);
  EXPECT_EQ(j["endcaps"][1]["reached"], false);
}

}  // namespace
}  // namespace tensegrity::ground
