// SPDX-License-Identifier: Apache-2.0
// Quitting the operator console never drops an emergency stop: an estop key
// followed at once by the quit key (`printf 'e\nq\n' | tensegrity console`) still
// lands on every end cap within the estop's bound, and the console reports it
// before it exits. End caps 0-2 (comms_test_node), domain 192.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <map>
#include <regex>
#include <thread>

#include "ground/command.hpp"
#include "tests/ground/console_link_fixture.hpp"

namespace tensegrity::ground {
namespace {

// From the 'e' written to the loop's ESTOPPED line: the console's 20 ms key poll,
// two estop retries, two loop periods of the stub (500 Hz), and what a loaded 2-core
// machine adds to wake-ups (tests/ground/estop_dds_test.cpp derives the same).
constexpr std::int64_t kBoundNs = 50'000'000 + 2 * 50'000'000 + 2 * 2'000'000 + 300'000'000;

// "ESTOPPED endcap=E true_ns=T" lines with T >= since: E -> T.
std::map<int, std::int64_t> estopped(const std::string& text, std::int64_t since) {
  std::map<int, std::int64_t> out;
  const std::regex line(R"(ESTOPPED endcap=(\d+) true_ns=(-?\d+))");
  for (std::sregex_iterator it(text.begin(), text.end(), line), end; it != end; ++it) {
    const std::int64_t t = std::stoll((*it)[2]);
    if (t >= since && out.count(std::stoi((*it)[1])) == 0) out[std::stoi((*it)[1])] = t;
  }
  return out;
}

std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), {}};
}

TEST_F(ConsoleLink, QuittingRightAfterAnEstopKeyStillLandsItAndReportsIt) {
  constexpr int kDomain = 192;
  const std::string domain = std::to_string(kDomain);
  const std::shared_ptr<Station> watcher = three_endcaps(kDomain);
  ASSERT_NE(watcher, nullptr);
  // The console's stdin: a FIFO held open here, so the keys arrive when written.
  const std::filesystem::path keys = dir_ / "keys";
  ASSERT_EQ(::mkfifo(keys.c_str(), 0600), 0);
  const int keys_fd = ::open(keys.c_str(), O_RDWR);
  ASSERT_GE(keys_fd, 0);
  test::Subprocess console({TENSEGRITY_CLI, "console", "--insecure", "--domain", domain, "--endcaps", "0-2", "--socket",
                            (dir_ / "c.sock").string()},
                           dir_ / "console.out", dir_ / "console.err", keys);
  ASSERT_TRUE(console.wait_for_output("hears 3 of 3", std::chrono::seconds(30)));

  const std::int64_t pressed = Station::now_ns();
  ASSERT_EQ(::write(keys_fd, "e\nq\n", 4), 4);
  const int code = console.wait_exit(std::chrono::seconds(40));
  ::close(keys_fd);
  const std::string out = read_file(dir_ / "console.out");
  const std::string err = read_file(dir_ / "console.err");
  EXPECT_EQ(code, 0) << out << err;

  // Every end cap latched the stop, in time, and the console said so before it left.
  const std::map<int, std::int64_t> seen = estopped(nodes_->output(), pressed);
  EXPECT_EQ(seen.size(), 3U) << "end caps that took the estop: " << seen.size() << "\n" << err;
  for (const auto& [e, t] : seen) EXPECT_LE(t - pressed, kBoundNs) << "end cap " << e;
  const auto counted = [&watcher] {
    int n = 0;
    for (std::size_t e = 0; e < 3; ++e) n += watcher->snapshot()[e].estops.count == 1U ? 1 : 0;
    return n;
  };
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(3);
  while (counted() < 3 && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(counted(), 3) << "end caps whose heartbeat counts one estop";
  EXPECT_NE(out.find("last command: estop"), std::string::npos) << out;
  int accepted = 0;
  std::istringstream rows(out);
  for (std::string row; std::getline(rows, row);) accepted += row.find("accepted") != std::string::npos ? 1 : 0;
  EXPECT_EQ(accepted, 3) << out;
}

}  // namespace
}  // namespace tensegrity::ground
