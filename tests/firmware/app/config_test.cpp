// SPDX-License-Identifier: Apache-2.0
// Config and policy-file errors name the field, so the log line alone says what to fix.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "firmware/app/config.hpp"
#include "firmware/app/control_loop.hpp"
#include "firmware/app/policy_file.hpp"

namespace tensegrity::fw::app {
namespace {

using ::testing::HasSubstr;
using json = nlohmann::json;

json example() {
  return json::parse(R"({
    "format": "tensegrity-endcap/1",
    "bus": "udp:127.0.0.1:47000,bind=127.0.0.1:47001",
    "nodes": {"drives": [1, 3], "load_cell": 2},
    "spool": {"radius_m": 0.01, "counts_per_rev": 446464},
    "limits": {"min_rest_length_m": 0.6, "max_rest_length_m": 1.1, "speed_m_per_s": 0.2,
               "cutoff_tension_n": 400, "hard_limit_tension_n": 500},
    "initial_rest_length_m": 0.95,
    "storage_dir": "/tmp/endcap",
    "loop": {"period_ns": 2000000, "mode": "lockstep"}
  })");
}

std::string error_of(const json& doc, int id = 3) {
  try {
    parse_config(doc.dump(), id, "endcap.json");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(EndcapConfig, ParsesAFullConfig) {
  const EndcapAppConfig c = parse_config(example().dump(), 3);
  EXPECT_EQ(c.endcap_id, 3);
  EXPECT_EQ(c.motor_count, 2U);
  EXPECT_EQ(c.drive_node_ids[1], 3);
  EXPECT_EQ(c.load_cell_node_id, 2);
  EXPECT_EQ(c.mode, LoopMode::lockstep);
  EXPECT_EQ(c.loop_period_ns, 2'000'000);
  EXPECT_DOUBLE_EQ(c.limits.hard_limit_tension_n, 500.0);
  EXPECT_EQ(c.limits.overload, core::Overload::hold) << "absent: the hardware guard";
  EXPECT_FALSE(c.start_on_boot);
}

TEST(EndcapConfig, TheShippedExampleParses) {
  const EndcapAppConfig c = load_config(ENDCAP_EXAMPLE_CONFIG, 0);
  EXPECT_EQ(c.mode, LoopMode::realtime);
  EXPECT_EQ(c.loop_period_ns, 1'000'000);
}

TEST(EndcapConfig, ErrorsNameTheField) {
  json j = example();
  j.erase("bus");
  EXPECT_THAT(error_of(j), HasSubstr("endcap.json: bus: missing"));

  j = example();
  j["bus"] = "can0";
  EXPECT_THAT(error_of(j), HasSubstr("endcap.json: bus: "));

  j = example();
  j["loop"]["mode"] = "fast";
  EXPECT_THAT(error_of(j), HasSubstr("loop.mode: must be \"realtime\" or \"lockstep\""));

  j = example();
  j["limits"]["max_rest_length_m"] = 0.5;
  EXPECT_THAT(error_of(j), HasSubstr("limits.max_rest_length_m: must be above min_rest_length_m"));

  j = example();
  j["limits"]["speed_m_per_s"] = "fast";
  EXPECT_THAT(error_of(j), HasSubstr("limits.speed_m_per_s: must be a number"));

  j = example();
  j["limits"]["hard_limit_n"] = 500;  // misspelt: must not fall back to a default silently
  EXPECT_THAT(error_of(j), HasSubstr("limits.hard_limit_n: unknown field"));

  j = example();
  j["limits"]["overload"] = "yield";
  EXPECT_THAT(error_of(j), HasSubstr("limits.overload: must be \"hold\" or \"pay_out\" (got \"yield\")"));

  j = example();
  j["nodes"]["drives"] = {1, 1};
  EXPECT_THAT(error_of(j), HasSubstr("nodes.drives[1]: node id used twice"));

  j = example();
  j["nodes"]["load_cell"] = 200;
  EXPECT_THAT(error_of(j), HasSubstr("nodes.load_cell: must be a CANopen node id 1..127"));

  j = example();
  j["spool"].erase("radius_m");
  EXPECT_THAT(error_of(j), HasSubstr("spool.radius_m: missing"));

  j = example();
  j["initial_rest_length_m"] = 2.0;
  EXPECT_THAT(error_of(j), HasSubstr("initial_rest_length_m: must lie within"));

  j = example();
  j["timeouts"] = {{"load_cell_sample_s", 0.001}};
  EXPECT_THAT(error_of(j), HasSubstr("timeouts.load_cell_sample_s"));

  EXPECT_THAT(error_of(example(), 12), HasSubstr("--id"));
  EXPECT_THAT(error_of(json::parse(R"({"format": "tensegrity-endcap/2"})")), HasSubstr("format"));
}

std::string policy_json(double value_for_cable_5) {
  json cables = json::array();
  for (int c = 0; c < 24; ++c) {
    cables.push_back({{"cable", c}, {"owner", c / 2}, {"rest_lengths_m", {0.9, c == 5 ? value_for_cable_5 : 1.0}}});
  }
  return json{{"format", "tensegrity-policy/1"},
              {"robot", "superball"},
              {"period_s", 1.2},
              {"complexity", 2},
              {"cables", cables}}
      .dump();
}

// One integer period, the one the drives are given (0x1006 in us, 0x60C2 as value
// x 10^index): a period they cannot be told is refused, naming the field.
TEST(EndcapConfig, TheLoopPeriodIsOneIntegerTheDrivesCanBeTold) {
  json j = example();
  j["loop"]["period_ns"] = 2'500'000;
  EXPECT_EQ(parse_config(j.dump(), 3).loop_period_ns, 2'500'000);
  for (const std::int64_t bad :
       {std::int64_t{99'000}, std::int64_t{2'000'000'000}, std::int64_t{1'000'500}, std::int64_t{1'234'000}}) {
    j["loop"]["period_ns"] = bad;
    EXPECT_THAT(error_of(j), HasSubstr("endcap.json: loop.period_ns: must be")) << bad;
  }
  j["loop"]["period_ns"] = 0.002;
  EXPECT_THAT(error_of(j), HasSubstr("endcap.json: loop.period_ns: must be an integer"));
  j["loop"].erase("period_ns");
  j["loop"]["rate_hz"] = 500;
  EXPECT_THAT(error_of(j), HasSubstr("endcap.json: loop.rate_hz: replaced by period_ns"));
  EXPECT_EQ(make_loop_settings(parse_config(example().dump(), 3)).master.sync_period_ns, 2'000'000);
}

TEST(EndcapConfig, SupervisionDefaultsAreDerivedFromTheLoop) {
  EndcapAppConfig c = parse_config(example().dump(), 3);  // 500 Hz
  EXPECT_EQ(c.endcap_node_id, 127);
  EXPECT_DOUBLE_EQ(c.endcap_heartbeat_s, 0.01);
  EXPECT_DOUBLE_EQ(c.drive_consumer_heartbeat_s, 0.05) << "five producer periods";
  EXPECT_DOUBLE_EQ(c.drive_position_timeout_s, 0.02);
  EXPECT_EQ(c.drive_abort_connection, canopen::AbortConnectionOption::quick_stop);
  json slow = example();
  slow["loop"]["period_ns"] = 25'000'000;  // 40 Hz: the producer beats once a cycle at most
  slow["timeouts"] = {{"load_cell_sample_s", 0.1}, {"drive_position_s", 0.1}};
  c = parse_config(slow.dump(), 3);
  EXPECT_DOUBLE_EQ(c.endcap_heartbeat_s, 0.025);
  EXPECT_DOUBLE_EQ(c.drive_consumer_heartbeat_s, 0.125);
  json given = example();
  given["nodes"]["endcap"] = 100;
  given["timeouts"] = {{"endcap_heartbeat_s", 0.02}, {"drive_position_s", 0.05}};
  given["drive_abort_connection"] = "disable_voltage";
  c = parse_config(given.dump(), 3);
  EXPECT_EQ(c.endcap_node_id, 100);
  EXPECT_DOUBLE_EQ(c.drive_consumer_heartbeat_s, 0.1) << "derived from the given producer period";
  EXPECT_DOUBLE_EQ(c.drive_position_timeout_s, 0.05);
  EXPECT_EQ(c.drive_abort_connection, canopen::AbortConnectionOption::disable_voltage);
}

// The writer and the reader are one schema: whatever a config holds comes back.
void expect_same(const EndcapAppConfig& a, const EndcapAppConfig& b) {
  EXPECT_EQ(a.endcap_id, b.endcap_id);
  EXPECT_EQ(a.bus, b.bus);
  EXPECT_EQ(a.motor_count, b.motor_count);
  EXPECT_EQ(a.drive_node_ids, b.drive_node_ids);
  EXPECT_EQ(a.use_load_cell, b.use_load_cell);
  if (a.use_load_cell) {
    EXPECT_EQ(a.load_cell_node_id, b.load_cell_node_id);
  }
  EXPECT_EQ(a.endcap_node_id, b.endcap_node_id);
  EXPECT_EQ(a.spool_radius_m, b.spool_radius_m);
  EXPECT_EQ(a.counts_per_rev, b.counts_per_rev);
  EXPECT_EQ(a.limits.min_rest_length_m, b.limits.min_rest_length_m);
  EXPECT_EQ(a.limits.max_rest_length_m, b.limits.max_rest_length_m);
  EXPECT_EQ(a.limits.speed_m_per_s, b.limits.speed_m_per_s);
  EXPECT_EQ(a.limits.cutoff_tension_n, b.limits.cutoff_tension_n);
  EXPECT_EQ(a.limits.hard_limit_tension_n, b.limits.hard_limit_tension_n);
  EXPECT_EQ(a.limits.overload, b.limits.overload);
  EXPECT_EQ(a.initial_rest_length_m, b.initial_rest_length_m);
  EXPECT_EQ(a.storage_dir, b.storage_dir);
  EXPECT_EQ(a.loop_period_ns, b.loop_period_ns);
  EXPECT_EQ(a.mode, b.mode);
  EXPECT_EQ(a.drive_heartbeat_timeout_s, b.drive_heartbeat_timeout_s);
  EXPECT_EQ(a.load_cell_heartbeat_timeout_s, b.load_cell_heartbeat_timeout_s);
  EXPECT_EQ(a.load_cell_sample_timeout_s, b.load_cell_sample_timeout_s);
  EXPECT_EQ(a.drive_position_timeout_s, b.drive_position_timeout_s);
  EXPECT_EQ(a.endcap_heartbeat_s, b.endcap_heartbeat_s);
  EXPECT_EQ(a.drive_consumer_heartbeat_s, b.drive_consumer_heartbeat_s);
  EXPECT_EQ(a.drive_abort_connection, b.drive_abort_connection);
  EXPECT_EQ(a.start_on_boot, b.start_on_boot);
  EXPECT_EQ(a.stats_log_period_s, b.stats_log_period_s);
  EXPECT_EQ(a.dds_keystore, b.dds_keystore);
}

TEST(EndcapConfig, WhatTheWriterWritesTheReaderReadsBack) {
  json full = example();
  full["nodes"] = {{"drives", {5}}, {"endcap", 100}};
  full["tension_guard"] = "off";
  full["timeouts"] = {{"drive_heartbeat_s", 0.25},  {"load_cell_heartbeat_s", 0.3},
                      {"load_cell_sample_s", 0.05}, {"drive_position_s", 0.04},
                      {"endcap_heartbeat_s", 0.02}, {"drive_consumer_heartbeat_s", 0.07}};
  full["limits"]["overload"] = "pay_out";
  full["drive_abort_connection"] = "fault";
  full["start_on_boot"] = true;
  full["stats_log_period_s"] = 2.5;
  full["dds_keystore"] = "/etc/tensegrity/keystore";
  for (const json& doc : {example(), full}) {
    const EndcapAppConfig c = parse_config(doc.dump(), 7);
    const std::string written = config_to_json_text(c);
    expect_same(parse_config(written, 7), c);
    EXPECT_EQ(config_to_json_text(parse_config(written, 7)), written) << "a fixed point";
  }
}

// Without a load cell no tension is measured, so neither the cut-off nor the hard
// limit holds: that is never what a null or a left-out node id means, only what
// a field named for it says.
TEST(EndcapConfig, TheTensionGuardGoesOffOnlyWhenNamed) {
  json j = example();
  j["nodes"]["load_cell"] = nullptr;
  EXPECT_THAT(error_of(j), HasSubstr("endcap.json: nodes.load_cell: null would turn the tension guard off"));
  EXPECT_THAT(error_of(j), HasSubstr("\"tension_guard\": \"off\""));
  j["nodes"].erase("load_cell");
  EXPECT_THAT(error_of(j), HasSubstr("nodes.load_cell: missing"));
  j["tension_guard"] = "off";
  EXPECT_FALSE(parse_config(j.dump(), 3).use_load_cell);
  j["nodes"]["load_cell"] = nullptr;
  EXPECT_FALSE(parse_config(j.dump(), 3).use_load_cell);
  j["nodes"]["load_cell"] = 2;
  EXPECT_THAT(error_of(j), HasSubstr("nodes.load_cell: a load cell with \"tension_guard\": \"off\""));
  j = example();
  j["tension_guard"] = "on";
  EXPECT_TRUE(parse_config(j.dump(), 3).use_load_cell);
  EXPECT_TRUE(parse_config(example().dump(), 3).use_load_cell);
  j["tension_guard"] = false;
  EXPECT_THAT(error_of(j), HasSubstr("tension_guard: must be"));
}

TEST(EndcapConfig, TheDdsKeystoreIsAFolderOrLeftOut) {
  json j = example();
  j.erase("dds_keystore");
  EXPECT_TRUE(parse_config(j.dump(), 1).dds_keystore.empty());
  j["dds_keystore"] = "/k";
  EXPECT_EQ(parse_config(j.dump(), 1).dds_keystore, std::filesystem::path("/k"));
  j["dds_keystore"] = "";
  EXPECT_THAT(error_of(j), HasSubstr("dds_keystore: must be a non-empty string"));
  j["dds_keystore"] = 3;
  EXPECT_THAT(error_of(j), HasSubstr("dds_keystore"));
}

TEST(EndcapConfig, SupervisionErrorsNameTheField) {
  const auto with = [](const char* key, const json& value) {
    json j = example();
    j["timeouts"][key] = value;
    return j;
  };
  EXPECT_THAT(error_of(with("endcap_heartbeat_s", 0.0105)),
              HasSubstr("timeouts.endcap_heartbeat_s: must be a whole number of milliseconds"));
  EXPECT_THAT(error_of(with("endcap_heartbeat_s", 0.001)),
              HasSubstr("timeouts.endcap_heartbeat_s: must be at least one loop period"));
  EXPECT_THAT(error_of(with("endcap_heartbeat_s", 70.0)), HasSubstr("timeouts.endcap_heartbeat_s"));
  EXPECT_THAT(error_of(with("drive_consumer_heartbeat_s", 0.015)),
              HasSubstr("timeouts.drive_consumer_heartbeat_s: must be at least twice endcap_heartbeat_s"));
  EXPECT_THAT(error_of(with("drive_position_s", 0.003)),
              HasSubstr("timeouts.drive_position_s: must be at least two loop periods"));
  EXPECT_THAT(error_of(with("drive_position_s", -1)), HasSubstr("timeouts.drive_position_s: must be > 0"));
  json j = example();
  j["drive_abort_connection"] = "none";
  EXPECT_THAT(error_of(j), HasSubstr("endcap.json: drive_abort_connection: must be \"quick_stop\""));
  j = example();
  j["nodes"]["endcap"] = 3;
  EXPECT_THAT(error_of(j), HasSubstr("nodes.endcap: node id used by a drive or the load cell too"));
  j = example();
  j["nodes"]["endcap"] = 128;
  EXPECT_THAT(error_of(j), HasSubstr("nodes.endcap: must be a CANopen node id 1..127"));
  j = example();
  j["nodes"]["drives"] = {1, 127};
  EXPECT_THAT(error_of(j), HasSubstr("nodes.endcap: the default end-cap node id 127 is taken"));
}

TEST(PolicyFile, TakesThisEndcapsCablesInIndexOrder) {
  const core::EndcapTable t = endcap_table_from_policy(policy_json(0.8), 2, 2, core::MotorLimits{});
  EXPECT_EQ(t.motor_count, 2U);
  EXPECT_EQ(t.complexity, 2U);
  EXPECT_DOUBLE_EQ(t.period_s, 1.2);
  EXPECT_DOUBLE_EQ(t.rest_length_m[0][1], 1.0);  // cable 4
  EXPECT_DOUBLE_EQ(t.rest_length_m[1][1], 0.8);  // cable 5
}

TEST(PolicyFile, ErrorsNameTheField) {
  const auto error = [](const std::string& text, int id) {
    try {
      endcap_table_from_policy(text, id, 2, core::MotorLimits{}, "p.json");
    } catch (const PolicyFileError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_THAT(error(policy_json(3.0), 2), HasSubstr("p.json: cables[5].rest_lengths_m[1]: 3 m is outside"));
  EXPECT_EQ(error(policy_json(3.0), 3), "(no error)") << "another end cap's cable is not ours to check";
  EXPECT_THAT(error(R"({"format": "tensegrity-policy/1", "period_s": 1, "complexity": 2, "cables": []})", 0),
              HasSubstr("cables: end cap 0 owns 0 cables"));
  EXPECT_THAT(error(R"({"format": "x"})", 0), HasSubstr("p.json: format"));
  EXPECT_THAT(error("{", 0), HasSubstr("not valid JSON"));
  // Found by fuzz/policy_file: a number too large for a double is bad JSON too,
  // not nlohmann's out_of_range escaping the documented error.
  EXPECT_THAT(error(R"({"format": "tensegrity-policy/1", "period_s": 1e30808})", 0), HasSubstr("not valid JSON"));
}

}  // namespace
}  // namespace tensegrity::fw::app

namespace tensegrity::fw::app {
namespace {
// Found by fuzz/endcap_config: a number too large for a double escaped as
// nlohmann's out_of_range instead of the documented ConfigError.
TEST(EndcapConfig, ANumberTooLargeForADoubleIsAConfigError) {
  EXPECT_THROW(parse_config(R"({"bus": "udp:127.0.0.1:1", "loop_rate_hz": 1e30808})", 3, "endcap.json"), ConfigError);
}
}  // namespace
}  // namespace tensegrity::fw::app
