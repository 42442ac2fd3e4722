// SPDX-License-Identifier: Apache-2.0
// The operator console (`tensegrity console`) and its local link: the protocol's
// validation, the socket's rules (one console per socket, a dead one's socket
// replaced, a private folder), an estop that preempts a stop in flight, and the
// program end to end: `tensegrity estop` sent through a running console to three
// end-cap nodes (comms_test_node). Domains 180-184 and 186.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <algorithm>
#include <fstream>
#include <future>
#include <random>
#include <sstream>
#include <thread>

#include "ground/operator_client.hpp"
#include "ground/operator_protocol.hpp"
#include "ground/operator_server.hpp"
#include "ground/station_keeper.hpp"
#include "ground/unix_socket.hpp"
#include "tests/ground/console_link_fixture.hpp"
#include "tests/ground/subprocess.hpp"

namespace tensegrity::ground {
namespace {

namespace fs = std::filesystem;
using test::Subprocess;

std::string refusal(const std::string& line) {
  try {
    decode_request(line);
  } catch (const OperatorLinkError& e) {
    return e.what();
  }
  return "";
}

TEST(OperatorProtocol, ARequestRoundTripsAndBadOnesAreRefusedByField) {
  const OperatorRequest sent{CommandKind::clear_fault, 0b101, 12.5};
  const OperatorRequest got = decode_request(encode_request(sent));
  EXPECT_EQ(got.kind, CommandKind::clear_fault);
  EXPECT_EQ(got.endcap_mask, 0b101);
  EXPECT_DOUBLE_EQ(got.timeout_s, 12.5);

  const std::string f = R"("format":"tensegrity-operator/1")";
  EXPECT_NE(refusal("{").find("not valid JSON"), std::string::npos);
  EXPECT_NE(refusal(R"({"format":"x","command":"estop","endcap_mask":1,"timeout_s":1})").find("format"),
            std::string::npos);
  // A start needs a time plan: the console does not relay it.
  EXPECT_NE(refusal("{" + f + R"(,"command":"start","endcap_mask":1,"timeout_s":1})").find("command: must be"),
            std::string::npos);
  EXPECT_NE(refusal("{" + f + R"(,"command":"estop","endcap_mask":0,"timeout_s":1})").find("endcap_mask"),
            std::string::npos);
  EXPECT_NE(refusal("{" + f + R"(,"command":"estop","endcap_mask":4096,"timeout_s":1})").find("endcap_mask"),
            std::string::npos);
  EXPECT_NE(refusal("{" + f + R"(,"command":"estop","endcap_mask":1,"timeout_s":-1})").find("timeout_s"),
            std::string::npos);
  EXPECT_NE(refusal("{" + f + R"(,"command":"estop","endcap_mask":1,"timeout_s":1,"x":1})").find("x: unknown"),
            std::string::npos);
}

TEST(OperatorProtocol, AReplyRoundTrips) {
  OperatorReply sent;
  sent.console_pid = 4242;
  sent.report.kind = CommandKind::emergency_stop;
  sent.report.rejoins = 1;
  EndcapCommandResult r;
  r.endcap = 7;
  r.acked = r.accepted = true;
  r.text = "accepted";
  r.latency_s = 0.004;
  sent.report.results = {r};
  const OperatorReply got = decode_reply(encode_reply(sent));
  EXPECT_EQ(got.console_pid, 4242);
  EXPECT_EQ(got.report.kind, CommandKind::emergency_stop);
  ASSERT_EQ(got.report.results.size(), 1U);
  EXPECT_EQ(got.report.results[0].endcap, 7);
  EXPECT_TRUE(got.report.results[0].accepted);
  EXPECT_DOUBLE_EQ(got.report.results[0].latency_s, 0.004);
  EXPECT_THROW(decode_reply(R"({"format":"tensegrity-operator/1"})"), OperatorLinkError);
}

TEST_F(ConsoleLink, OneListenerPerSocketAndADeadOnesSocketIsReplaced) {
  const fs::path path = dir_ / "c.sock";
  EXPECT_FALSE(ask_console(path, OperatorRequest{}).has_value());  // nobody there: the tool speaks itself
  {
    UniqueFd first = listen_unix(path, 4);
    struct stat st {};
    ASSERT_EQ(::stat(path.c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0600U);
    EXPECT_THROW(listen_unix(path, 4), std::runtime_error);
  }  // closed without unlinking, as a killed console leaves it
  ASSERT_TRUE(fs::exists(path));
  EXPECT_FALSE(ask_console(path, OperatorRequest{}).has_value());
  EXPECT_NO_THROW(listen_unix(path, 4));
  std::ofstream(dir_ / "plain") << "x";
  EXPECT_THROW(listen_unix(dir_ / "plain", 4), std::runtime_error);
  // In a folder others may enter, whatever answers is not taken for the console.
  fs::permissions(dir_, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec,
                  fs::perm_options::replace);
  EXPECT_THROW(ask_console(path, OperatorRequest{}), OperatorLinkError);
}

TEST_F(ConsoleLink, TheServerMakesItsFolderPrivateAndRefusesABadRequestByName) {
  StationOptions o;
  o.domain = 182;
  o.publish_heartbeat = false;
  o.serve_time = false;
  auto station = std::make_shared<Station>(o);
  fs::permissions(dir_, fs::perms::all);
  const fs::path path = dir_ / "sub" / "c.sock";
  OperatorServer server([station] { return station; }, path);
  EXPECT_EQ(fs::status(path.parent_path()).permissions() & fs::perms::all, fs::perms::owner_all);
  fs::create_directories(dir_ / "open");  // 0755: the server does not take it over
  EXPECT_THROW(OperatorServer([station] { return station; }, dir_ / "open" / "c.sock"), OperatorLinkError);
  EXPECT_THROW(OperatorServer([station] { return station; }, path), OperatorLinkError);  // one console per socket

  UniqueFd fd = connect_unix(path);
  ASSERT_TRUE(fd);
  write_all(fd.get(), R"({"format":"tensegrity-operator/1","command":"estop","endcap_mask":0,"timeout_s":1})"
                      "\n");
  const OperatorReply reply = decode_reply(read_line(fd.get(), 1 << 16, std::chrono::seconds(10)));
  EXPECT_NE(reply.error.find("endcap_mask"), std::string::npos) << reply.error;
  EXPECT_EQ(server.refused(), 1U);
}

// End caps 0-2 answer; a stop addressed to 0-3 waits for end cap 3 until its
// deadline, unless an emergency stop takes over: the estop then lands at once.
TEST_F(ConsoleLink, AnEstopPreemptsAStopInFlight) {
  const std::shared_ptr<Station> station = three_endcaps(180);
  ASSERT_TRUE(station) << "end caps 0-2 or the station did not come up";
  OperatorServer server([station] { return station; }, dir_ / "c.sock");

  const std::int64_t t0 = Station::now_ns();
  auto stop = std::async(std::launch::async, [&] { return server.run({CommandKind::stop, 0b1111, 20.0}); });
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // end caps 0-2 acked; 3 never will
  const std::int64_t asked = Station::now_ns();
  const std::optional<OperatorReply> estop =
      ask_console(dir_ / "c.sock", OperatorRequest{CommandKind::emergency_stop, 0b111, 10.0});
  const std::int64_t answered_ns = Station::now_ns() - asked;
  const CommandReport stopped = stop.get();
  const double elapsed_s = static_cast<double>(Station::now_ns() - t0) / 1e9;

  EXPECT_TRUE(stopped.preempted);
  const std::vector<int> missing = stopped.missing();
  EXPECT_NE(std::find(missing.begin(), missing.end(), 3), missing.end());
  EXPECT_LT(elapsed_s, 15.0) << "the stop ran to its 20 s deadline: the estop did not take over";
  ASSERT_TRUE(estop.has_value());
  EXPECT_TRUE(estop->error.empty()) << estop->error;
  EXPECT_TRUE(estop->report.all_accepted()) << format_command_report(estop->report);
  EXPECT_EQ(estop->report.results.size(), 3U);
  double worst = 0;
  for (const auto& r : estop->report.results) worst = std::max(worst, r.latency_s);
  std::printf(
      "MEASURE console estop after preempting a stop: last ack %.1f ms, reply %.1f ms, stop ended after %.2f s\n",
      worst * 1e3, static_cast<double>(answered_ns) / 1e6, elapsed_s);
  // From the request to every ack: the stop notices the estop at its next check
  // (kPreemptCheckNs, 20 ms), the estop's first write or its retry lands (2 x 50 ms),
  // plus what a loaded 2-core machine adds to wake-ups (estop_dds_test's 300 ms).
  constexpr std::int64_t kBoundNs = 20'000'000 + 2 * 50'000'000 + 300'000'000;
  EXPECT_LE(answered_ns, kBoundNs) << "the estop through the console took too long to land on all three";
}

// An estop for end cap 3 (absent) is preempted by a newer estop for end cap 0: the
// newer one takes end cap 3 over, so no end cap an estop was meant for is dropped.
TEST_F(ConsoleLink, ANewerEstopTakesOverTheEndcapsAnOlderOneMissed) {
  const std::shared_ptr<Station> station = three_endcaps(186);
  ASSERT_TRUE(station) << "end caps 0-2 or the station did not come up";
  OperatorServer server([station] { return station; }, dir_ / "c.sock");
  auto older = std::async(std::launch::async, [&] { return server.run({CommandKind::emergency_stop, 0b1000, 20.0}); });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const CommandReport newer = server.run({CommandKind::emergency_stop, 0b0001, 2.0});
  const CommandReport first = older.get();
  EXPECT_TRUE(first.preempted);
  ASSERT_EQ(newer.results.size(), 2U) << format_command_report(newer);
  EXPECT_TRUE(newer.results[0].accepted) << "end cap 0";
  EXPECT_EQ(newer.missing(), std::vector<int>{3}) << "end cap 3 was carried over, and is absent";
}

// A station that hears nobody (here: made on another domain, as a stalled security
// handshake leaves one) is replaced by one that hears the end caps; an end cap that
// is simply off does not make the keeper swap a working station.
TEST_F(ConsoleLink, TheKeeperReplacesAStationThatHearsNobody) {
  constexpr int kDomain = 183;
  Subprocess nodes({COMMS_TEST_NODE, "--domain", std::to_string(kDomain), "--endcaps", "0-2"}, dir_ / "nodes.out",
                   dir_ / "nodes.err");
  ASSERT_TRUE(nodes.wait_for_output("READY", std::chrono::seconds(20)));
  int made = 0;
  auto make = [&made] {
    StationOptions o;
    o.domain = made++ == 0 ? kDomain + 1 : kDomain;  // the first one hears nothing
    return std::make_unique<Station>(o);
  };
  StationKeeper::Options keep;
  keep.expected = 0b1111;  // end cap 3 never answers
  keep.stall_s = 0.5;
  keep.trial_s = 5.0;  // room for a fresh participant's discovery on a loaded machine
  StationKeeper keeper(make, keep);
  const std::shared_ptr<Station> first = keeper.current();
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (keeper.rejoins() == 0 && std::chrono::steady_clock::now() < until) {
    keeper.tick(Station::now_ns());
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_EQ(keeper.rejoins(), 1);
  const std::shared_ptr<Station> second = keeper.current();
  EXPECT_NE(second, first);
  EXPECT_EQ(StationKeeper::linked(*second, 0b1111, Station::now_ns(), 2.0), 0b111);
  // Now only the absent end cap 3 is missing: candidates come and go, none wins.
  const auto watch = std::chrono::steady_clock::now() + std::chrono::seconds(4);
  while (std::chrono::steady_clock::now() < watch) {
    keeper.tick(Station::now_ns());
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(keeper.rejoins(), 1);
  EXPECT_EQ(keeper.current(), second);
  EXPECT_GE(made, 3) << "no candidate was tried while end cap 3 stayed missing";
}

// The program: a console process, and `tensegrity estop` finding it by --console.
TEST_F(ConsoleLink, TheEstopToolSendsThroughARunningConsole) {
  constexpr int kDomain = 181;
  const std::string domain = std::to_string(kDomain);
  Subprocess nodes({COMMS_TEST_NODE, "--domain", domain, "--endcaps", "0-2"}, dir_ / "nodes.out", dir_ / "nodes.err");
  ASSERT_TRUE(nodes.wait_for_output("READY", std::chrono::seconds(20)));
  const std::string socket = (dir_ / "c.sock").string();
  Subprocess console(
      {TENSEGRITY_CLI, "console", "--insecure", "--domain", domain, "--endcaps", "0-2", "--socket", socket},
      dir_ / "console.out", dir_ / "console.err");
  ASSERT_TRUE(console.wait_for_output("hears 3 of 3", std::chrono::seconds(30)));

  Subprocess estop({TENSEGRITY_CLI, "estop", "--insecure", "--domain", domain, "--endcaps", "0-2", "--console", socket},
                   dir_ / "estop.out", dir_ / "estop.err");
  EXPECT_EQ(estop.wait_exit(std::chrono::seconds(60)), 0);
  std::ifstream o(dir_ / "estop.out"), e(dir_ / "estop.err");
  const std::string out((std::istreambuf_iterator<char>(o)), {});
  const std::string err((std::istreambuf_iterator<char>(e)), {});
  EXPECT_NE(err.find("sent by the console"), std::string::npos) << err;
  int accepted = 0;  // rows "E  accepted  latency  reason"
  std::istringstream rows(out);
  for (std::string row; std::getline(rows, row);) accepted += row.find("accepted") != std::string::npos ? 1 : 0;
  EXPECT_EQ(accepted, 3) << out;
  std::ifstream ce(dir_ / "console.err");
  const std::string console_err((std::istreambuf_iterator<char>(ce)), {});
  EXPECT_NE(console_err.find("relayed estop: 3 of 3 acked"), std::string::npos) << console_err;

  // Without a console at a named socket the tool says so instead of speaking itself.
  Subprocess lost({TENSEGRITY_CLI, "estop", "--insecure", "--domain", domain, "--endcaps", "0-2", "--console",
                   (dir_ / "none.sock").string()},
                  dir_ / "lost.out", dir_ / "lost.err");
  EXPECT_EQ(lost.wait_exit(std::chrono::seconds(30)), 1);
}

}  // namespace
}  // namespace tensegrity::ground
