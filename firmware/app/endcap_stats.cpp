// SPDX-License-Identifier: Apache-2.0
#include "firmware/app/endcap_stats.hpp"

#include <cstdio>
#include <fstream>
#include <type_traits>

#include <nlohmann/json.hpp>

namespace tensegrity::fw::app {
namespace {

using json = nlohmann::json;

json timing_json(const TimingStats& t) {
  return {{"count", t.count}, {"p50_us", t.p50_us}, {"p99_us", t.p99_us}, {"max_us", t.max_us}};
}

// Field access that names the field (and where it sits) when it is missing or of
// the wrong type, instead of nlohmann's "type must be number, but is null".
class Fields {
 public:
  Fields(const json& j, std::string source, std::string path)
      : j_(j), source_(std::move(source)), path_(std::move(path)) {
    if (!j_.is_object()) fail("", "must be an object");
  }
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    const std::string field =
        path_.empty() ? (key.empty() ? "(top level)" : key) : (key.empty() ? path_ : path_ + "." + key);
    throw StatsError(source_ + ": " + field + ": " + what);
  }
  template <typename T>
  T get(const char* key) const {
    if (!j_.contains(key)) fail(key, "missing");
    const json& v = j_.at(key);
    if (!has_type<T>(v)) fail(key, std::string("must be ") + expected<T>());
    try {
      return v.get<T>();
    } catch (const json::exception&) {  // out of T's range
      fail(key, std::string("must be ") + expected<T>());
    }
  }
  bool null_or_absent(const char* key) const { return !j_.contains(key) || j_.at(key).is_null(); }
  Fields object(const char* key) const {
    if (!j_.contains(key)) fail(key, "missing");
    return Fields(j_.at(key), source_, path_.empty() ? key : path_ + "." + key);
  }

 private:
  // nlohmann converts -1 to a uint64_t and 2.5 to an int without a word.
  template <typename T>
  static bool has_type(const json& v) {
    if constexpr (std::is_same_v<T, bool>)
      return v.is_boolean();
    else if constexpr (std::is_same_v<T, std::string>)
      return v.is_string();
    else if constexpr (std::is_unsigned_v<T>)
      return v.is_number_unsigned();
    else if constexpr (std::is_integral_v<T>)
      return v.is_number_integer();
    else
      return v.is_number();
  }
  template <typename T>
  static const char* expected() {
    if constexpr (std::is_same_v<T, bool>)
      return "true or false";
    else if constexpr (std::is_same_v<T, std::string>)
      return "a string";
    else if constexpr (std::is_unsigned_v<T>)
      return "a count (an integer >= 0)";
    else if constexpr (std::is_integral_v<T>)
      return "an integer";
    else
      return "a number";
  }
  const json& j_;
  std::string source_, path_;
};

TimingStats parse_timing(const Fields& f) {
  return {f.get<std::uint64_t>("count"), f.get<double>("p50_us"), f.get<double>("p99_us"), f.get<double>("max_us")};
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
        {"loop_stalls", s.link.loop_stalls}}},
      {"cycle", s.cycle ? timing_json(*s.cycle) : json(nullptr)},
      {"wakeup_latency", s.wakeup_latency ? timing_json(*s.wakeup_latency) : json(nullptr)},
      {"table", table},
  };
}

EndcapStats parse_stats(const json& j, const std::string& source) {
  const Fields f(j, source, "");
  if (f.get<std::string>("format") != EndcapStats::kFormat) {
    f.fail("format", std::string("expected \"") + EndcapStats::kFormat + "\"");
  }
  EndcapStats s;
  s.final = f.get<bool>("final");
  s.endcap = f.get<int>("endcap");
  s.mode = f.get<std::string>("mode");
  s.rate_hz = f.get<double>("rate_hz");
  s.cycles = f.get<std::uint64_t>("cycles");
  s.overruns = f.get<std::uint64_t>("overruns");
  s.stalls = f.get<std::uint64_t>("stalls");
  s.late_wakeups = f.get<std::uint64_t>("late_wakeups");
  s.syncs_received = f.get<std::uint64_t>("syncs_received");
  s.send_failures = f.get<std::uint64_t>("send_failures");
  s.rx_drops = f.get<std::uint64_t>("rx_drops");
  s.drain_limited_cycles = f.get<std::uint64_t>("drain_limited_cycles");
  s.fault = f.get<std::string>("fault");
  s.bring_up = f.get<std::string>("bring_up");
  s.vm_rss_kb = f.get<long>("vm_rss_kb");
  const Fields link = f.object("link");
  s.link = {link.get<std::uint64_t>("host_losses"), link.get<std::uint64_t>("host_returns"),
            link.get<std::uint64_t>("link_cuts"), link.get<std::uint64_t>("loop_stalls")};
  if (!f.null_or_absent("cycle")) s.cycle = parse_timing(f.object("cycle"));
  if (!f.null_or_absent("wakeup_latency")) s.wakeup_latency = parse_timing(f.object("wakeup_latency"));
  if (!f.null_or_absent("table")) {
    const Fields t = f.object("table");
    TablePhase p{t.get<double>("period_s"), t.get<std::int64_t>("loop_time_ns"), t.get<std::int64_t>("table_time_ns"),
                 t.get<std::int64_t>("origin_loop_ns"), std::nullopt};
    if (!t.null_or_absent("loop_clock_origin_ns")) p.loop_clock_origin_ns = t.get<std::int64_t>("loop_clock_origin_ns");
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
  const std::filesystem::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << to_json(stats).dump(2) << "\n";
    if (!out.flush()) return false;
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  return !ec;
}

}  // namespace tensegrity::fw::app
