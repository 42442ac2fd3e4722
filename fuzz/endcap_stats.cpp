// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: an end cap's stats file (firmware/app/endcap_stats.hpp), as
// `tensegrity stats` and the HIL's report read it back.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include <nlohmann/json.hpp>

#include "firmware/app/endcap_stats.hpp"

namespace app = tensegrity::fw::app;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const nlohmann::json j = nlohmann::json::parse(data, data + size, nullptr, false);
  if (j.is_discarded()) return 0;  // not JSON: load_stats reports the parser's error
  try {
    const app::EndcapStats stats = app::parse_stats(j, "fuzz");
    // What parses must write back to a file that parses to the same.
    const nlohmann::json written = app::to_json(stats);
    if (app::to_json(app::parse_stats(written, "fuzz written")) != written) std::abort();
  } catch (const app::StatsError&) {
  }
  return 0;
}
