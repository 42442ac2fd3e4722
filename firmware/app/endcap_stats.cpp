// SPDX-License-Identifier: Apache-2.0
#include "firmware/app/endcap_stats.hpp"

#include <cstdio>
#include <fstream>
#include <system_error>

#include <nlohmann/json.hpp>

#include "format/atomic_file.hpp"
#include "format/json_reader.hpp"

namespace tensegrity::fw::app {
namespace {

using json = nlohmann::json;

json timing_json(const TimingStats& t) {
  return {{"count", t.count}, {"p50_us", t.p50_us}, {"p99_us", t.p99_us}, {"max_us", t.max_us}};
}

using Fields = format::JsonReader<StatsError>;

TimingStats parse_timing(const Fields& f) {
  return {f.count("count"), f.number("p50_us"), f.number("p99_us"), f.number("max_us")};
}

}  // namespace

json to_json(const EndcapStats& s) {
  json table = nullptr;
  if (s.table) {
    table = {{"period_s", s.table->period_s},
             {"loop_time_ns", s.table->loop_time_ns},
             {"table_time_ns", s.table->table_time_ns},
             {"origin_loop_ns", s.table->origin_loop_ns}};
    if (s.table->loop_clock_origin_ns) table["loop_clock_origin_ns"] = *s.table->loop_clock_origin_ns;
  }
  return {
      {"format", EndcapStats::kFormat},
      {"final", s.final},
      {"endcap", s.endcap},
      {"mode", s.mode},
      {"rate_hz", s.rate_hz},
      {"cycles", s.cycles},
      {"overruns", s.overruns},
      {"stalls", s.stalls},
      {"late_wakeups", s.late_wakeups},
      {"syncs_received", s.syncs_received},
      {"send_failures", s.send_failures},
      {"rx_drops", s.rx_drops},
      {"drain_limited_cycles", s.drain_limited_cycles},
      {"fault", s.fault},
      {"bring_up", s.bring_up},
      {"vm_rss_kb", s.vm_rss_kb},
      {"link",
       {{"host_losses", s.link.host_losses},
        {"host_returns", s.link.host_returns},
        {"link_cuts", s.link.link_cuts},
        {"loop_stalls", s.link.loop_stalls},
        {"rejoins", s.link.rejoins}}},
      {"cycle", s.cycle ? timing_json(*s.cycle) : json(nullptr)},
      {"wakeup_latency", s.wakeup_latency ? timing_json(*s.wakeup_latency) : json(nullptr)},
      {"table", table},
  };
}

EndcapStats parse_stats(const json& j, const std::string& source) {
  const Fields f(j, source, "");
  if (f.string("format") != EndcapStats::kFormat) {
    f.fail("format", std::string("expected \"") + EndcapStats::kFormat + "\"");
  }
  EndcapStats s;
  s.final = f.boolean("final");
  s.endcap = static_cast<int>(f.integer("endcap"));
  s.mode = f.string("mode");
  s.rate_hz = f.number("rate_hz");
  s.cycles = f.count("cycles");
  s.overruns = f.count("overruns");
  s.stalls = f.count("stalls");
  s.late_wakeups = f.count("late_wakeups");
  s.syncs_received = f.count("syncs_received");
  s.send_failures = f.count("send_failures");
  s.rx_drops = f.count("rx_drops");
  s.drain_limited_cycles = f.count("drain_limited_cycles");
  s.fault = f.string("fault");
  s.bring_up = f.string("bring_up", true);
  s.vm_rss_kb = static_cast<long>(f.integer("vm_rss_kb"));
  const Fields link = f.object("link");
  s.link = {link.count("host_losses"), link.count("host_returns"), link.count("link_cuts"), link.count("loop_stalls"),
            link.count("rejoins")};
  if (!f.null_or_absent("cycle")) s.cycle = parse_timing(f.object("cycle"));
  if (!f.null_or_absent("wakeup_latency")) s.wakeup_latency = parse_timing(f.object("wakeup_latency"));
  if (!f.null_or_absent("table")) {
    const Fields t = f.object("table");
    TablePhase p{t.number("period_s"), t.integer("loop_time_ns"), t.integer("table_time_ns"),
                 t.integer("origin_loop_ns"), std::nullopt};
    if (!t.null_or_absent("loop_clock_origin_ns")) p.loop_clock_origin_ns = t.integer("loop_clock_origin_ns");
    if (!(p.period_s > 0.0)) t.fail("period_s", "must be > 0");
    s.table = p;
  }
  return s;
}

EndcapStats load_stats(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw StatsError(path.string() + ": cannot be read");
  json j;
  try {
    j = json::parse(in);
  } catch (const json::parse_error& e) {
    throw StatsError(path.string() + ": not JSON (" + e.what() + ")");
  }
  return parse_stats(j, path.string());
}

bool write_stats(const std::filesystem::path& path, const EndcapStats& stats) {
  try {
    format::write_file_atomic(path, to_json(stats).dump(2) + "\n", format::Durability::atomic_only);
    return true;
  } catch (const std::system_error&) {
    return false;
  }
}

}  // namespace tensegrity::fw::app
