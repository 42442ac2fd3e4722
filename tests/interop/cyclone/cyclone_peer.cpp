// SPDX-License-Identifier: Apache-2.0
// cyclone_peer: a host-side peer of the end caps built on Eclipse Cyclone DDS
// instead of Fast DDS. It listens to the end caps' telemetry, then (with
// --upload-version) uploads a policy table to each one and waits for the
// acceptance acks, as `tensegrity upload` does. Used by cyclone_interop_tests;
// also runs by hand against real end caps or the HIL (same domain, CYCLONEDDS_URI
// allowing the network they are on).
//
//   cyclone_peer --domain D [--endcaps 0-11] [--listen-s 2] [--timeout-s 15]
//                [--upload-version N [--upload-repeat K] [--bad-checksum-first] [--motor-count 2]]
//
// Prints one line per finding (TOPIC, SEEN, TELEMETRY, ACK, ACTIVE, MEASURE) and
// "RESULT ok" with exit code 0, or "RESULT fail: ..." with 1; 2 for bad arguments.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "tests/interop/cyclone/peer.hpp"

namespace {

using namespace tensegrity::interop;

// "0-11", "3", "0,2,5-7" -> mask; throws std::invalid_argument.
std::uint16_t parse_endcaps(const std::string& text) {
  std::uint16_t mask = 0;
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t comma = text.find(',', at);
    const std::string part = text.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    std::size_t used_lo = 0, used_hi = 0;
    const std::size_t dash = part.find('-');
    const std::string lo_text = part.substr(0, dash);
    const std::string hi_text = dash == std::string::npos ? lo_text : part.substr(dash + 1);
    int lo = -1, hi = -1;
    try {
      lo = std::stoi(lo_text, &used_lo);
      hi = std::stoi(hi_text, &used_hi);
    } catch (const std::exception&) {
    }
    if (used_lo != lo_text.size() || used_hi != hi_text.size() || lo < 0 || hi >= kEndcapCount || lo > hi) {
      throw std::invalid_argument("--endcaps '" + text + "': bad part '" + part + "' (end caps are 0..11)");
    }
    for (int i = lo; i <= hi; ++i) mask = static_cast<std::uint16_t>(mask | (1U << i));
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  return mask;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"cyclone_peer: a Cyclone DDS host peer of the end caps (telemetry in, policy tables out)"};
  int domain = -1;
  std::string endcaps = "0-11";
  double listen_s = 2.0;
  double timeout_s = 15.0;
  std::int64_t version = 0;
  bool bad_checksum_first = false;
  int repeat = 1;
  PolicyParams params;
  cli.add_option("--domain", domain, "DDS domain id")->required()->check(CLI::Range(0, 232));
  cli.add_option("--endcaps", endcaps, "End caps expected, e.g. 0-11 or 0,3,5-7")->capture_default_str();
  cli.add_option("--listen-s", listen_s, "Seconds of telemetry to count")->check(CLI::Range(0.1, 3600.0));
  cli.add_option("--timeout-s", timeout_s, "Seconds to wait for telemetry, and for acks")
      ->check(CLI::Range(0.1, 3600.0));
  cli.add_option("--upload-version", version, "Upload policy 'cyclone_peer' with this version (0: no upload)")
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{0xFFFFFFFF}));
  cli.add_option("--upload-repeat", repeat, "Upload this many successive versions (latency statistics)")
      ->check(CLI::Range(1, 1000));
  cli.add_flag("--bad-checksum-first", bad_checksum_first, "First send one table with a wrong checksum");
  cli.add_option("--motor-count", params.motor_count, "Motors per end cap")->check(CLI::Range(1, 4));
  CLI11_PARSE(cli, argc, argv);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // the test reads the lines as they come

  std::uint16_t mask = 0;
  try {
    mask = parse_endcaps(endcaps);
    params.policy_version = static_cast<std::uint32_t>(version);
    if (version > 0) validate(params);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cyclone_peer: %s\n", e.what());
    return 2;
  }
  try {
    Peer peer(domain, mask);
    if (!peer.wait_for_telemetry(timeout_s)) {
      std::printf("RESULT fail: not every end cap's telemetry arrived\n");
      return 1;
    }
    if (!peer.listen(listen_s)) {
      std::printf("RESULT fail: telemetry stopped or was refused\n");
      return 1;
    }
    if (version > 0) {
      const int first = std::countr_zero(mask);
      if (bad_checksum_first && !peer.upload_bad_checksum(params, first, timeout_s)) {
        std::printf("RESULT fail: a table with a wrong checksum was not rejected as bad_checksum\n");
        return 1;
      }
      // Successive versions; the first one's acks are printed and checked in
      // detail by the test, every one must be accepted.
      std::vector<double> latencies_ms;
      for (int i = 0; i < repeat; ++i) {
        double latency_ms = 0.0;
        if (!peer.upload(params, timeout_s, latency_ms)) {
          std::printf("RESULT fail: not every end cap accepted policy version %u\n", params.policy_version);
          return 1;
        }
        latencies_ms.push_back(latency_ms);
        if (i == 0) peer.quiet();
        if (i + 1 < repeat) ++params.policy_version;
      }
      std::sort(latencies_ms.begin(), latencies_ms.end());
      const auto at = [&](double p) {
        const auto k = static_cast<std::size_t>(std::ceil(p * static_cast<double>(latencies_ms.size())));
        return latencies_ms[std::min(latencies_ms.size(), std::max<std::size_t>(k, 1)) - 1];
      };
      std::printf(
          "MEASURE cyclone_upload endcaps=%d uploads=%zu first_write_to_last_ack_ms median=%.2f p99=%.2f "
          "max=%.2f\n",
          std::popcount(mask), latencies_ms.size(), at(0.5), at(0.99), latencies_ms.back());
      if (!peer.wait_active(params, timeout_s)) {
        std::printf("RESULT fail: the end caps' telemetry does not report the uploaded policy as active\n");
        return 1;
      }
    }
  } catch (const std::exception& e) {
    std::printf("RESULT fail: %s\n", e.what());
    return 1;
  }
  std::printf("RESULT ok\n");
  return 0;
}
