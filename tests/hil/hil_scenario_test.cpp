// SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>

#include "hil/hil_error.hpp"
#include "hil/scenario.hpp"

namespace tensegrity::hil {
namespace {

// A scenario of one event: its error, or "accepted".
std::string refused(const std::string& event) {
  try {
    parse_scenario("[" + event + "]", 12, "s.json");
  } catch (const HilError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(HilScenario, ParsesSortsAndDefaults) {
  const Scenario s = parse_scenario(R"({"format": "tensegrity-hil-scenario/1", "events": [
      {"time_s": 3.0, "endcap": 4, "fault": "kill_endcap"},
      {"time_s": 1.5, "endcap": 3, "fault": "drive_fault", "params": {"motor": 1, "release": true}},
      {"time_s": 2.0, "endcap": 5, "fault": "corrupt_frames", "params": {"probability": 0.2, "kind": "datagram"}},
      {"time_s": 4.0, "fault": "cut_dds"}]})",
                                    12);
  ASSERT_EQ(s.events.size(), 4u);
  EXPECT_EQ(s.events[0].fault, FaultKind::drive_fault);
  EXPECT_EQ(s.events[0].params.motor, 1);
  EXPECT_TRUE(s.events[0].params.release);
  EXPECT_EQ(s.events[0].params.code, 0x2310);
  EXPECT_EQ(s.events[1].params.corrupt_kind, CorruptKind::datagram);
  EXPECT_EQ(s.events[2].fault, FaultKind::kill_endcap);
  EXPECT_EQ(s.events[3].fault, FaultKind::cut_dds);
  EXPECT_EQ(s.events[3].endcap, -1) << "no endcap: every end cap's link";
  EXPECT_NE(s.events[3].describe().find("all end caps: cut_dds"), std::string::npos);
}

TEST(HilScenario, ErrorsNameTheField) {
  const auto message = [](const std::string& text) {
    try {
      parse_scenario(text, 12, "s.json");
    } catch (const HilError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(R"([{"time_s": 1, "endcap": 12, "fault": "kill_endcap"}])"),
            "s.json: events[0].endcap: endcap 12 out of range 0..11");
  EXPECT_NE(message(R"([{"time_s": 1, "endcap": 1, "fault": "explode"}])").find("unknown fault 'explode'"),
            std::string::npos);
  EXPECT_EQ(message(R"([{"time_s": 1, "endcap": 1, "fault": "drop_frames", "params": {"probabilty": 1}}])"),
            "s.json: events[0].params.probabilty: unknown parameter");
}

// Integers are read without narrowing: 4294967295 is not motor -1 (every motor), 65536
// is not EMCY code 0, 4294967296 is not end cap 0.
TEST(HilScenario, BigIntegersAreRefusedNotWrapped) {
  EXPECT_EQ(refused(R"({"time_s": 1, "endcap": 1, "fault": "drive_fault", "params": {"motor": 4294967295}})"),
            "s.json: events[0].params.motor: an integer -1..3");
  EXPECT_EQ(refused(R"({"time_s": 1, "endcap": 1, "fault": "drive_fault", "params": {"motor": -9223372036854775808}})"),
            "s.json: events[0].params.motor: an integer -1..3");
  EXPECT_EQ(refused(R"({"time_s": 1, "endcap": 1, "fault": "drive_fault", "params": {"code": 65536}})"),
            "s.json: events[0].params.code: an integer 0..65535");
  EXPECT_EQ(refused(R"({"time_s": 1, "endcap": 4294967296, "fault": "kill_endcap"})"),
            "s.json: events[0].endcap: endcap 4294967296 out of range 0..11");
  EXPECT_EQ(refused(R"({"time_s": 1, "endcap": 18446744073709551615, "fault": "kill_endcap"})"),
            "s.json: events[0].endcap: endcap 18446744073709551615 out of range 0..11");
  EXPECT_EQ(refused(R"({"time_s": 1, "endcap": 1.5, "fault": "kill_endcap"})"), "s.json: events[0].endcap: an integer");
  EXPECT_EQ(refused(R"({"time_s": 1, "endcap": 1, "fault": "drive_fault", "params": {"motor": -1, "code": 65535}})"),
            "accepted");
}

// A parameter the fault does not read is refused like a misspelt one: a scenario must
// not look like it asks for something the run will not do.
TEST(HilScenario, AParameterTheFaultIgnoresIsRefused) {
  EXPECT_EQ(refused(R"({"time_s": 1, "endcap": 2, "fault": "kill_endcap", "params": {"motor": 1}})"),
            "s.json: events[0].params.motor: not a parameter of kill_endcap (it takes none)");
  EXPECT_EQ(refused(R"({"time_s": 1, "endcap": 2, "fault": "drop_frames", "params": {"kind": "frame"}})"),
            "s.json: events[0].params.kind: not a parameter of drop_frames (its parameters: probability, duration_s)");
  EXPECT_EQ(refused(R"({"time_s": 1, "endcap": 2, "fault": "load_cell_stuck", "params": {"n_per_s": 3}})"),
            "s.json: events[0].params.n_per_s: not a parameter of load_cell_stuck (it takes none)");
  EXPECT_EQ(refused(R"({"time_s": 1, "endcap": 2, "fault": "load_cell_drift", "params": {"n_per_s": 3}})"), "accepted");
  EXPECT_EQ(refused(R"({"time_s": 1, "endcap": 2, "fault": "seize_spool", "params": {"motor": 1}})"), "accepted");
  EXPECT_EQ(refused(R"({"time_s": 1, "endcap": 2, "fault": "corrupt_frames", "params": {"kind": "datagram",
            "probability": 1, "duration_s": 2}})"),
            "accepted");
}

TEST(HilScenario, FaultOption) {
  const ScenarioEvent e = parse_fault_option("3:drive_silent@2.5", 12);
  EXPECT_EQ(e.endcap, 3);
  EXPECT_EQ(e.fault, FaultKind::drive_silent);
  EXPECT_DOUBLE_EQ(e.time_s, 2.5);
  EXPECT_THROW(parse_fault_option("3-drive_silent", 12), HilError);
  EXPECT_EQ(parse_fault_option("all:cut_dds@5", 12).endcap, -1);
  EXPECT_EQ(parse_fault_option("4:restore_dds@6.5", 12).endcap, 4);
  EXPECT_EQ(parse_fault_option("all:mute_dds@5", 12).endcap, -1);
  EXPECT_EQ(parse_fault_option("7:mute_dds@1", 12).fault, FaultKind::mute_dds);
  EXPECT_EQ(parse_scenario(R"([{"time_s": 1, "fault": "mute_dds"}])", 12).events.at(0).endcap, -1);
  EXPECT_THROW(parse_fault_option("all:kill_endcap@5", 12), HilError);  // "all" only for the link
  EXPECT_THROW(parse_fault_option("3:kill_endcap@5x", 12), HilError);
  EXPECT_THROW(parse_fault_option("3:kill_endcap@inf", 12), HilError);
  EXPECT_THROW(parse_fault_option("3:kill_endcap@nan", 12), HilError);
  EXPECT_THROW(parse_fault_option(" 3:kill_endcap@1", 12), HilError);
  EXPECT_THROW(parse_fault_option("+3:kill_endcap@1", 12), HilError);
  EXPECT_THROW(parse_fault_option("3000000000:kill_endcap@1", 12), HilError);
}

TEST(HilScenario, SupervisionFaults) {
  const Scenario s = parse_scenario(R"([
      {"time_s": 1.0, "endcap": 3, "fault": "reboot_drive", "params": {"motor": 1}},
      {"time_s": 2.0, "endcap": 4, "fault": "reboot_load_cell"},
      {"time_s": 3.0, "endcap": 5, "fault": "hang_loop"},
      {"time_s": 4.0, "endcap": 6, "fault": "stop_endcap"}])",
                                    12);
  ASSERT_EQ(s.events.size(), 4u);
  EXPECT_EQ(s.events[0].fault, FaultKind::reboot_drive);
  EXPECT_EQ(s.events[0].params.motor, 1);
  EXPECT_NE(s.events[0].describe().find("end cap 3: reboot_drive (motor 1)"), std::string::npos);
  EXPECT_EQ(s.events[1].fault, FaultKind::reboot_load_cell);
  EXPECT_EQ(s.events[2].fault, FaultKind::hang_loop);
  EXPECT_EQ(s.events[3].fault, FaultKind::stop_endcap);
  EXPECT_EQ(parse_fault_option("7:hang_loop@2", 12).fault, FaultKind::hang_loop);
  EXPECT_EQ(parse_fault_option("7:stop_endcap@2", 12).fault, FaultKind::stop_endcap);
  EXPECT_THROW(parse_fault_option("all:stop_endcap@2", 12), HilError);
  EXPECT_THROW(parse_scenario(R"([{"time_s": 1, "fault": "hang_loop"}])", 12), HilError) << "needs an end cap";
}

// An operator's commands: every end cap unless one is named; they take no parameters.
TEST(HilScenario, OperatorCommands) {
  const Scenario s = parse_scenario(R"([{"time_s": 3, "fault": "start"}, {"time_s": 1, "fault": "estop"},
      {"time_s": 2, "endcap": 5, "fault": "clear_fault"}])",
                                    12);
  ASSERT_EQ(s.events.size(), 3u);
  EXPECT_EQ(s.events[0].fault, FaultKind::estop);
  EXPECT_EQ(s.events[0].endcap, -1);
  EXPECT_EQ(s.events[1].fault, FaultKind::clear_fault);
  EXPECT_EQ(s.events[1].endcap, 5);
  EXPECT_EQ(s.events[2].fault, FaultKind::start);
  EXPECT_EQ(parse_fault_option("all:estop@4", 12).endcap, -1);
  EXPECT_EQ(parse_fault_option("2:start@4", 12).fault, FaultKind::start);
  EXPECT_TRUE(is_operator_command(FaultKind::clear_fault));
  EXPECT_FALSE(is_operator_command(FaultKind::cut_dds));
  EXPECT_THROW(parse_scenario(R"([{"time_s": 1, "fault": "estop", "params": {"motor": 0}}])", 12), HilError);
  Scenario all;
  all.events = {parse_fault_option("all:estop@1", 12)};
  EXPECT_NO_THROW(check_scenario(all, sim::load_robot(sim::robot_path_named("superball"))));
}

// The parser takes motors -1..3 and end caps below the count it is given; the robot
// decides the rest before the run starts, not 30 s into it.
TEST(HilScenario, EventsAreCheckedAgainstTheRobotBeforeTheRun) {
  const sim::Robot robot = sim::load_robot(sim::robot_path_named("superball"));  // 2 motors per end cap
  const auto check = [&robot](const std::string& option) {
    Scenario s;
    s.events = {parse_fault_option("1:kill_endcap@0.5", 16), parse_fault_option(option, 16)};
    try {
      check_scenario(s, robot);
    } catch (const HilError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(check("3:seize_spool@1"), "accepted");
  EXPECT_EQ(check("all:cut_dds@1"), "accepted");
  EXPECT_EQ(check("12:kill_endcap@1"),
            "scenario event 1 (t=1 s end cap 12: kill_endcap): the robot has end caps 0..11");
  Scenario s = parse_scenario(R"([{"time_s": 2, "endcap": 4, "fault": "drive_fault", "params": {"motor": 2}},
                                  {"time_s": 3, "endcap": 4, "fault": "drive_silent", "params": {"motor": -1}}])",
                              12);
  try {
    check_scenario(s, robot);
    ADD_FAILURE() << "motor 2 of a 2-motor end cap accepted";
  } catch (const HilError& e) {
    EXPECT_EQ(std::string(e.what()),
              "scenario event 0 (t=2 s end cap 4: drive_fault (motor 2, EMCY 0x2310, holding)): end cap 4 has motors "
              "0..1 (-1: all)");
  }
  s.events.erase(s.events.begin());
  EXPECT_NO_THROW(check_scenario(s, robot)) << "-1: every motor";
}

TEST(HilScenario, DisabledCableFaultsItsOwnersDriveAndReleasesIt) {
  const sim::Robot robot = sim::load_robot(sim::robot_path_named("superball"));
  // Cable 3 (nodes 0-10) is owned by end cap 10, whose cables are 3 and 16.
  const ScenarioEvent e = disabled_cable_event(robot, 3);
  EXPECT_EQ(e.endcap, 10);
  EXPECT_EQ(e.fault, FaultKind::drive_fault);
  EXPECT_EQ(robot.cables_of(10).at(static_cast<std::size_t>(e.params.motor)), 3);
  EXPECT_TRUE(e.params.release);
  EXPECT_DOUBLE_EQ(e.time_s, 0.0);
  EXPECT_THROW(disabled_cable_event(robot, 24), HilError);
  // Only the spool: the drive does not fault, the end cap keeps its other cable.
  const ScenarioEvent spool = disabled_cable_event(robot, 3, CableFailure::spool);
  EXPECT_EQ(spool.fault, FaultKind::release_spool);
  EXPECT_EQ(spool.params.motor, e.params.motor);
  EXPECT_EQ(parse_fault_option("10:release_spool@0", 12).fault, FaultKind::release_spool);
  EXPECT_EQ(disabled_cable_event(robot, 3, CableFailure::seize).fault, FaultKind::seize_spool);
}

}  // namespace
}  // namespace tensegrity::hil
