// SPDX-License-Identifier: Apache-2.0
// A clear-fault through the operator console never undoes an emergency stop the
// operator had not seen when asking: one queued behind another command names the
// estop counts of its asking, and `tensegrity clear-fault` whose relayed clear an
// estop preempted does not send it again from its own participant (which would name
// the counts after that estop). End caps 0-2 (comms_test_node), domains 188-189 and 193.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <fstream>
#include <future>
#include <thread>

#include "core/fault.hpp"
#include "ground/command.hpp"
#include "ground/operator_protocol.hpp"
#include "ground/operator_server.hpp"
#include "tests/ground/console_link_fixture.hpp"

namespace tensegrity::ground {
namespace {

using fw::comms::CommandReason;

bool all_estopped(const Station& station, std::uint16_t mask) {
  const auto status = station.snapshot();
  for (int e = 0; e < kEndcapCount; ++e) {
    if ((mask & (1U << e)) == 0) continue;
    if (status[e].heartbeat.fault() != static_cast<std::uint8_t>(core::FaultCause::emergency_stop)) return false;
  }
  return true;
}

bool wait_estopped(const Station& station, std::uint16_t mask) {
  const std::int64_t until = Station::now_ns() + 5'000'000'000;
  while (!all_estopped(station, mask) && Station::now_ns() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return all_estopped(station, mask);
}

// Another tool, on its own participant, that hears end caps 0-2 (null if it does not).
std::unique_ptr<Station> another_tool(int domain) {
  StationOptions o;
  o.domain = domain;
  o.name = "console_clear_other_tool";
  auto other = std::make_unique<Station>(o);
  if (!other->wait_for_endcaps(0b111, false, Station::now_ns() + 20'000'000'000)) return nullptr;
  return other;
}

CommandReport estop(Station& station) {
  CommandOptions co;
  co.endcap_mask = 0b111;
  co.retry_interval_s = kEstopRetryIntervalS;
  return send_command(station, CommandKind::emergency_stop, 0, co);
}

// A stop for 0-3 holds the console (end cap 3 never answers); a clear-fault for 0-2
// is asked meanwhile, then another tool's estop lands. When the stop gives up, the
// clear goes out naming the counts from before that estop: every end cap refuses it.
TEST_F(ConsoleLink, AClearQueuedBehindAStopDoesNotUndoAnEstopThatLandedMeanwhile) {
  constexpr int kDomain = 188;
  const std::shared_ptr<Station> station = three_endcaps(kDomain);
  ASSERT_TRUE(station) << "end caps 0-2 or the station did not come up";
  const std::unique_ptr<Station> other = another_tool(kDomain);
  ASSERT_TRUE(other) << "the other tool hears no end cap";
  OperatorServer server([station] { return station; }, dir_ / "c.sock");
  auto stop = std::async(std::launch::async, [&] { return server.run({CommandKind::stop, 0b1111, 10.0}); });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  auto clear = std::async(std::launch::async, [&] { return server.run({CommandKind::clear_fault, 0b111, 10.0}); });
  for (int i = 0; i < 2000 && server.asked() < 2; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_EQ(server.asked(), 2U) << "the clear never reached the console";
  const CommandReport stopped = estop(*other);
  ASSERT_TRUE(stopped.all_accepted()) << format_command_report(stopped);
  ASSERT_TRUE(wait_estopped(*station, 0b111));
  EXPECT_FALSE(stop.get().preempted) << "the stop ran to its deadline: the estop was not the console's";
  const CommandReport cleared = clear.get();
  ASSERT_EQ(cleared.results.size(), 3U) << format_command_report(cleared);
  for (const auto& r : cleared.results) {
    EXPECT_TRUE(r.acked) << "end cap " << r.endcap;
    EXPECT_EQ(r.reason, CommandReason::estop_unseen) << "end cap " << r.endcap << ": " << r.text;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_TRUE(all_estopped(*station, 0b111)) << "the queued clear undid the estop";
}

// A clear-fault asked before its tool heard any end cap (a fresh `tensegrity
// clear-fault --no-console` joining the domain) while another tool's estop lands
// meanwhile: the end caps it hears afterwards report the count with that estop in
// it, yet the estop came after the asking, so every end cap refuses the clear.
TEST_F(ConsoleLink, AClearAskedBeforeItsToolHeardTheEndcapsDoesNotUndoAnEstopLandedMeanwhile) {
  constexpr int kDomain = 193;
  const std::shared_ptr<Station> station = three_endcaps(kDomain);
  ASSERT_TRUE(station) << "end caps 0-2 or the station did not come up";
  auto asked = std::make_shared<EstopsSeen>(estops_asked_now());  // nothing heard yet
  const CommandReport stopped = estop(*station);                  // the console's estop
  ASSERT_TRUE(stopped.all_accepted()) << format_command_report(stopped);
  ASSERT_TRUE(wait_estopped(*station, 0b111));
  const std::unique_ptr<Station> late = another_tool(kDomain);  // hears each count with the estop in it
  ASSERT_TRUE(late) << "the late tool hears no end cap";
  CommandOptions co;
  co.endcap_mask = 0b111;
  co.timeout_s = 10.0;
  co.estops_seen = asked;
  const CommandReport cleared = send_command(*late, CommandKind::clear_fault, 0, co);
  ASSERT_EQ(cleared.results.size(), 3U) << format_command_report(cleared);
  for (const auto& r : cleared.results) {
    EXPECT_TRUE(r.acked) << "end cap " << r.endcap;
    EXPECT_EQ(r.reason, CommandReason::estop_unseen) << "end cap " << r.endcap << ": " << r.text;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_TRUE(all_estopped(*station, 0b111)) << "the stale clear undid the estop";

  // Asked now, after the estop: it clears.
  co.estops_seen = std::make_shared<EstopsSeen>(estops_asked_now());
  const CommandReport fresh = send_command(*late, CommandKind::clear_fault, 0, co);
  EXPECT_TRUE(fresh.all_accepted()) << format_command_report(fresh);
}

// `tensegrity clear-fault` finds the console on its default socket; the console's
// clear waits to hear end cap 3 (absent; the console's station is new, so it waits
// up to kClearHearWaitS) when an estop through the console preempts it. The tool must report that and exit 1, not
// send the clear again itself.
TEST_F(ConsoleLink, TheClearFaultToolDoesNotResendAClearAnEstopPreempted) {
  constexpr int kDomain = 189;
  ASSERT_EQ(::setenv("XDG_RUNTIME_DIR", dir_.c_str(), 1), 0);  // the default socket, here (children inherit it)
  const std::shared_ptr<Station> station = three_endcaps(kDomain);
  ASSERT_TRUE(station) << "end caps 0-2 or the station did not come up";
  StationOptions o;
  o.domain = kDomain;
  const auto fresh = std::make_shared<Station>(o);
  OperatorServer server([fresh] { return fresh; }, default_console_socket(kDomain));
  const std::string domain = std::to_string(kDomain);
  test::Subprocess tool({TENSEGRITY_CLI, "clear-fault", "--insecure", "--domain", domain, "--endcaps", "0-3"},
                        dir_ / "clear.out", dir_ / "clear.err");
  // The console has the clear (it waits to hear end cap 3) before the estop.
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (server.asked() < 1 && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_EQ(server.asked(), 1U) << "the tool never reached the console";
  const CommandReport stopped = server.run({CommandKind::emergency_stop, 0b111, 5.0});
  EXPECT_TRUE(stopped.all_accepted()) << format_command_report(stopped);
  EXPECT_EQ(tool.wait_exit(std::chrono::seconds(60)), 1);
  ::unsetenv("XDG_RUNTIME_DIR");
  std::ifstream err_file(dir_ / "clear.err");
  const std::string err((std::istreambuf_iterator<char>(err_file)), {});
  EXPECT_NE(err.find("not sent"), std::string::npos) << err;
  EXPECT_EQ(err.find("own participant"), std::string::npos) << err;
  ASSERT_TRUE(wait_estopped(*station, 0b111));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_TRUE(all_estopped(*station, 0b111)) << "a clear undid the estop";
}

}  // namespace
}  // namespace tensegrity::ground
