// SPDX-License-Identifier: Apache-2.0
#include "ground/operator_protocol.hpp"

#include <unistd.h>

#include <cstdlib>
#include <iterator>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "format/json_reader.hpp"

namespace tensegrity::ground {
namespace {

using json = nlohmann::json;
using Reader = format::JsonReader<OperatorLinkError>;

// What the console relays: a start needs a time plan and a synchronized station,
// which `tensegrity start` makes itself.
// Names as command.cpp's to_string spells them; this library stands alone so that
// its fuzzer links without the DDS station.
constexpr CommandKind kRelayed[] = {CommandKind::emergency_stop, CommandKind::stop, CommandKind::clear_fault};
constexpr const char* kRelayedNames[] = {"estop", "stop", "clear-fault"};

const char* relayed_name(CommandKind kind) {
  for (std::size_t i = 0; i < std::size(kRelayed); ++i) {
    if (kRelayed[i] == kind) return kRelayedNames[i];
  }
  throw std::invalid_argument("operator link: a console relays estop, stop and clear-fault only");
}
constexpr std::uint8_t kLastReason = static_cast<std::uint8_t>(fw::comms::CommandReason::no_table);

Reader top_level(const json& j, const char* what) {
  Reader r(j, what, "");
  if (r.string("format") != kOperatorFormat) r.fail("format", std::string("must be \"") + kOperatorFormat + "\"");
  return r;
}

std::uint16_t read_mask(const Reader& r) {
  const std::uint64_t mask = r.count("endcap_mask");
  if (mask == 0 || (mask & ~std::uint64_t{kAllEndcaps}) != 0) {
    r.fail("endcap_mask", "must address some of end caps 0..11 (1..4095)");
  }
  return static_cast<std::uint16_t>(mask);
}

json encode_result(const EndcapCommandResult& r) {
  return {{"endcap", r.endcap},     {"acked", r.acked},
          {"accepted", r.accepted}, {"reason", static_cast<int>(r.reason)},
          {"text", r.text},         {"latency_s", r.latency_s}};
}

EndcapCommandResult decode_result(const Reader& r) {
  r.only({"endcap", "acked", "accepted", "reason", "text", "latency_s"});
  EndcapCommandResult out;
  const std::uint64_t endcap = r.count("endcap");
  if (endcap >= kEndcapCount) r.fail("endcap", "must be 0..11");
  out.endcap = static_cast<int>(endcap);
  out.acked = r.boolean("acked");
  out.accepted = r.boolean("accepted");
  const std::uint64_t reason = r.count("reason");
  if (reason > kLastReason) r.fail("reason", "unknown command reason code");
  out.reason = static_cast<fw::comms::CommandReason>(reason);
  out.text = r.string("text", true);
  out.latency_s = r.non_negative("latency_s");
  return out;
}

CommandKind read_kind(const Reader& r) {
  const std::size_t i = r.choice("command", {kRelayedNames[0], kRelayedNames[1], kRelayedNames[2]}, 3);
  if (i == 3) r.fail("command", "missing");
  return kRelayed[i];
}

}  // namespace

std::string encode_request(const OperatorRequest& request) {
  return json{{"format", kOperatorFormat},
              {"command", relayed_name(request.kind)},
              {"endcap_mask", request.endcap_mask},
              {"timeout_s", request.timeout_s}}
      .dump();
}

OperatorRequest decode_request(const std::string& line) {
  const json j = format::parse_json<OperatorLinkError>(line, "request");
  const Reader r = top_level(j, "request");
  r.only({"format", "command", "endcap_mask", "timeout_s"});
  OperatorRequest out;
  out.kind = read_kind(r);
  out.endcap_mask = read_mask(r);
  out.timeout_s = r.positive("timeout_s", 0.0, true);
  if (out.timeout_s > kMaxOperatorTimeoutS) r.fail("timeout_s", "must be <= 3600 s");
  return out;
}

std::string encode_reply(const OperatorReply& reply) {
  json results = json::array();
  for (const auto& r : reply.report.results) results.push_back(encode_result(r));
  return json{{"format", kOperatorFormat},
              {"error", reply.error},
              {"console_pid", reply.console_pid},
              {"command", relayed_name(reply.report.kind)},
              {"rejoins", reply.report.rejoins},
              {"preempted", reply.report.preempted},
              {"results", results}}
      .dump(-1, ' ', false, json::error_handler_t::replace);  // ack texts: the end caps' bytes, maybe not UTF-8
}

OperatorReply decode_reply(const std::string& line) {
  const json j = format::parse_json<OperatorLinkError>(line, "reply");
  const Reader r = top_level(j, "reply");
  r.only({"format", "error", "console_pid", "command", "rejoins", "preempted", "results"});
  OperatorReply out;
  out.error = r.string("error", true);
  out.console_pid = static_cast<long>(r.count("console_pid"));
  out.report.kind = read_kind(r);
  out.report.rejoins = static_cast<int>(r.count("rejoins"));
  out.report.preempted = r.boolean("preempted");
  const json& results = r.array("results");
  if (results.size() > kEndcapCount) r.fail("results", "more than 12 end caps");
  for (std::size_t i = 0; i < results.size(); ++i) {
    out.report.results.push_back(decode_result(Reader(results[i], "reply", "results[" + std::to_string(i) + "]")));
  }
  return out;
}

std::filesystem::path default_console_socket(int domain) {
  const std::string name = "console-" + std::to_string(domain) + ".sock";
  const char* runtime = std::getenv("XDG_RUNTIME_DIR");
  if (runtime != nullptr && runtime[0] == '/') return std::filesystem::path(runtime) / "tensegrity" / name;
  return std::filesystem::path("/tmp") / ("tensegrity-" + std::to_string(::geteuid())) / name;
}

}  // namespace tensegrity::ground
