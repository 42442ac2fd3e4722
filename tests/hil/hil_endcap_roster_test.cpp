// SPDX-License-Identifier: Apache-2.0
// The roster of end caps with fake programs and a fake clock: admission when a
// program listens (rate-limited), boot's failure on an exited program, the wait
// for a restarted one, the start gate and one tick's answers.
#include <gtest/gtest.h>

#include "firmware/drivers/pdo_codec.hpp"
#include "hil/endcap_roster.hpp"
#include "hil/hil_error.hpp"
#include "hil_fakes.hpp"
#include "robot/robot.hpp"

namespace tensegrity::hil {
namespace {

using hil_test::FakeClock;
using hil_test::FakeProcesses;

const sim::Robot& robot() {
  static const sim::Robot r = sim::load_robot(sim::robot_path_named("superball"));
  return r;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const HilError& e) {
    return e.what();
  }
  return "no error";
}

TEST(HilEndcapRoster, AdmitsListeningProgramsAtMostOncePerPeriod) {
  FakeProcesses processes;
  EndcapRoster roster(robot(), fw::SpoolGeometry{}, true, processes);
  ASSERT_EQ(roster.size(), 12);
  processes.listening_set = {0, 5};
  roster.admit_listening(1'000'000'000);
  EXPECT_EQ(roster.state(0), EndcapState::live);
  EXPECT_EQ(roster.state(5), EndcapState::live);
  EXPECT_EQ(roster.state(1), EndcapState::waiting_process);
  const int checks = processes.listening_checks;
  processes.listening_set.insert(1);
  roster.admit_listening(1'000'000'000 + EndcapRoster::kCheckPeriodNs / 2);
  EXPECT_EQ(processes.listening_checks, checks) << "within the check period: /proc not read again";
  EXPECT_EQ(roster.state(1), EndcapState::waiting_process);
  roster.admit_listening(1'000'000'000 + EndcapRoster::kCheckPeriodNs);
  EXPECT_EQ(roster.state(1), EndcapState::live);
  for (int e = 0; e < 12; ++e) processes.listening_set.insert(e);
  roster.admit_listening(2'000'000'000);
  const int all = processes.listening_checks;
  roster.admit_listening(3'000'000'000);
  EXPECT_EQ(processes.listening_checks, all) << "nobody waiting: nothing to check";
}

TEST(HilEndcapRoster, BootFailsAtOnceOnAnExitedProgramAndReportsTheMissing) {
  FakeProcesses processes;
  EndcapRoster roster(robot(), fw::SpoolGeometry{}, true, processes);
  for (int e = 0; e < 12; ++e) {
    if (e != 7) processes.listening_set.insert(e);
  }
  roster.admit_listening(1'000'000'000);
  EXPECT_FALSE(roster.all_at_gate());
  const std::string report = roster.boot_report(30'000'000'000);
  EXPECT_NE(report.find("within 30 s: end cap 0 drive node 1 "), std::string::npos) << report;
  EXPECT_NE(report.find("end cap 7 has no bus socket (fake 7);"), std::string::npos) << report;
  EXPECT_NO_THROW(roster.fail_on_exit(1'000'000'000));
  processes.exited_set = {3};
  EXPECT_EQ(error_of([&] { roster.fail_on_exit(1'000'000'000 + EndcapRoster::kCheckPeriodNs); }),
            "boot: end cap 3's program exited before the start gate: fake 3");
}

TEST(HilEndcapRoster, WaitsForARestartedProgramAndNamesOneThatExits) {
  FakeProcesses processes;
  FakeClock clock;
  EndcapRoster roster(robot(), fw::SpoolGeometry{}, true, processes);
  for (int e = 0; e < 12; ++e) processes.listening_set.insert(e);
  roster.admit_listening(clock.now);
  roster.restart(4);
  EXPECT_EQ(processes.restarted, std::vector<int>{4});
  EXPECT_EQ(processes.killed, std::vector<int>{4}) << "a live program is killed before its restart";
  EXPECT_EQ(roster.state(4), EndcapState::waiting_process);
  std::stop_source stop;
  roster.await_restarted(clock, stop.get_token(), 1'000'000'000, 7);  // it listens at once
  EXPECT_EQ(roster.state(4), EndcapState::live);

  roster.kill(4);
  EXPECT_EQ(roster.state(4), EndcapState::down);
  roster.restart(4);
  EXPECT_EQ(processes.killed.size(), 2u) << "not killed twice";
  processes.listening_set.erase(4);
  clock.wake_late = [&](int sleep) -> std::int64_t {
    if (sleep == 5) processes.exited_set.insert(4);
    return 0;
  };
  const std::string why = error_of([&] { roster.await_restarted(clock, stop.get_token(), 1'000'000'000, 7); });
  EXPECT_EQ(why,
            "lockstep: end cap 4's restarted program exited before it listened on its bus (physics step 7): fake 4");
  processes.exited_set.clear();
  EXPECT_NE(error_of([&] {
              roster.await_restarted(clock, stop.get_token(), 1'000'000'000, 9);
            }).find("not listening on its bus within 1 s (physics step 9): end cap 4 (fake 4);"),
            std::string::npos);
  stop.request_stop();
  EXPECT_EQ(error_of([&] { roster.await_restarted(clock, stop.get_token(), 1'000'000'000, 9); }), "interrupted");
}

TEST(HilEndcapRoster, OneTicksAnswersNameTheMissingDriveNodes) {
  FakeProcesses processes;
  EndcapRoster roster(robot(), fw::SpoolGeometry{}, true, processes);
  EXPECT_FALSE(roster.any_expected());
  EXPECT_TRUE(roster.all_answered());
  roster.expect(3, true);
  roster.expect(9, true);
  EXPECT_TRUE(roster.first_answer_expected());
  FrameOut out;
  roster.devices(3).power_on(0, out);
  roster.devices(9).power_on(0, out);
  roster.devices(3).on_frame(fw::canopen::encode_drive_rpdo1(1, {0x0F, 0}), 0, out);
  roster.devices(3).on_frame(fw::canopen::encode_drive_rpdo1(3, {0x0F, 0}), 0, out);
  roster.devices(9).on_frame(fw::canopen::encode_drive_rpdo1(3, {0x0F, 0}), 0, out);
  EXPECT_FALSE(roster.all_answered());
  EXPECT_EQ(roster.missing_answers(), " end cap 9 sent no RPDO1 for drive node(s) 1 (fake 9);");
  roster.devices(9).on_frame(fw::canopen::encode_drive_rpdo1(1, {0x0F, 0}), 0, out);
  EXPECT_TRUE(roster.all_answered());
  roster.answered();
  EXPECT_FALSE(roster.first_answer_expected()) << "the next answers are the usual kind";
}

}  // namespace
}  // namespace tensegrity::hil
