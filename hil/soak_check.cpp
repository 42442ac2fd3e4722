// SPDX-License-Identifier: Apache-2.0
#include "hil/soak_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace tensegrity::hil {

namespace {

std::string fixed(double value, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, value);
  return buf;
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto i = static_cast<std::size_t>(p * static_cast<double>(values.size() - 1) + 0.5);
  return values[std::min(i, values.size() - 1)];
}

constexpr std::size_t kRssWindow = 5;  // samples averaged at each end (1 Hz: 5 s)

}  // namespace

std::string SoakViolation::describe() const {
  std::string s = invariant;
  if (time_s >= 0.0) s += " at " + fixed(time_s, 3) + " s";
  if (endcap >= 0) s += ", end cap " + std::to_string(endcap);
  return s + ": " + detail;
}

void SoakChecker::add(const std::string& invariant, double t_s, int endcap, const std::string& detail) {
  violations_.push_back({invariant, t_s, endcap, detail});
}

void SoakChecker::tension(double t_s, double max_tension_n) {
  ++checked_["tension"];
  max_tension_n_ = std::max(max_tension_n_, max_tension_n);
  if (max_tension_n <= bounds_.tension_limit_n || tension_reported_) return;
  tension_reported_ = true;  // the running maximum: once over, every later step is too
  add("tension", t_s, -1,
      fixed(max_tension_n, 1) + " N, above the hard limit " + fixed(bounds_.tension_limit_n, 1) + " N");
}

void SoakChecker::estop(double t_s, const std::vector<SoakAck>& acks) {
  ++estops_;
  for (int e = 0; e < endcaps_; ++e) {
    if (!timeline_.must_reach(e, t_s)) continue;
    ++checked_["estop"];
    const SoakAck a = static_cast<std::size_t>(e) < acks.size() ? acks[static_cast<std::size_t>(e)] : SoakAck{};
    if (!a.acked) {
      add("estop", t_s, e,
          std::string("never acknowledged (running, on the link); ") + (a.taken   ? "its heartbeat shows the stop taken"
                                                                        : a.heard ? "its heartbeats show no stop taken"
                                                                                  : "no heartbeat of it heard"));
      continue;
    }
    estop_latencies_s_.push_back(a.latency_s);
    if (a.latency_s > bounds_.estop_s) {
      add("estop", t_s, e,
          "acknowledged after " + fixed(a.latency_s * 1e3, 1) + " ms, bound " + fixed(bounds_.estop_s * 1e3, 1) +
              " ms");
    }
  }
}

void SoakChecker::table(double t_s, int endcap, std::uint32_t life, const std::string& policy_id, std::uint32_t version,
                        double heard_for_s) {
  // Before physics step 0 the run's table is still on its way (the upload).
  if (t_s <= 0.0) return;
  ++checked_["table"];
  if (table_.first.empty() && !policy_id.empty()) table_ = {policy_id, version};
  const bool lost = policy_id.empty() && heard_for_s >= bounds_.table_grace_s;
  const bool mixed = !policy_id.empty() && std::make_pair(policy_id, version) != table_;
  if (!lost && !mixed) return;
  bool& reported = table_reported_[{endcap, life}];
  if (reported) return;  // once per life: a heartbeat every 0.2 s would repeat it
  reported = true;
  add("table", t_s, endcap,
      lost ? "no table " + fixed(heard_for_s, 1) + " s into its life"
           : "plays " + policy_id + " v" + std::to_string(version) + ", the run's is " + table_.first + " v" +
                 std::to_string(table_.second));
}

void SoakChecker::host_losses(int endcap, std::uint64_t losses) {
  ++checked_["host_loss"];
  const int cuts = timeline_.cuts_of(endcap);
  losses_ += losses;
  cuts_ += cuts;
  if (losses > static_cast<std::uint64_t>(cuts)) {
    add("host_loss", -1.0, endcap,
        std::to_string(losses) + " host loss(es), only " + std::to_string(cuts) + " cut(s) of its link");
  }
}

std::pair<std::int64_t, std::int64_t> rss_start_end(const std::vector<RssSample>& samples, const SoakBounds& bounds) {
  if (samples.empty()) return {-1, -1};
  const double from_s = samples.front().time_s + bounds.memory_warmup_s;
  const auto first =
      std::find_if(samples.begin(), samples.end(), [&](const RssSample& s) { return s.time_s >= from_s; });
  const auto n = static_cast<std::size_t>(samples.end() - first);
  if (n < 2 * kRssWindow || samples.back().time_s - first->time_s < bounds.memory_min_span_s) return {-1, -1};
  const auto mean = [](auto b, auto e) {
    return std::accumulate(b, e, std::int64_t{0},
                           [](std::int64_t sum, const RssSample& s) { return sum + s.rss_bytes; }) /
           static_cast<std::int64_t>(e - b);
  };
  return {mean(first, first + kRssWindow), mean(samples.end() - kRssWindow, samples.end())};
}

void SoakChecker::memory(const std::string& process, const std::vector<RssSample>& samples) {
  const auto [start, end] = rss_start_end(samples, bounds_);
  nlohmann::json j{{"process", process}, {"samples", samples.size()}};
  // Every 10th sample (MiB), to see a plateau from a leak in a long run.
  nlohmann::json trace = nlohmann::json::array();
  for (std::size_t i = 0; i < samples.size(); i += 10) {
    trace.push_back(std::round(static_cast<double>(samples[i].rss_bytes) / 1048576.0 * 100.0) / 100.0);
  }
  j["rss_mib_every_10"] = trace;
  if (start < 0) {
    j["judged"] = false;  // a life too short (a restarted end cap near the end)
    memory_.push_back(j);
    return;
  }
  ++checked_["memory"];
  const std::int64_t allowed = std::max(
      bounds_.memory_slack_bytes, static_cast<std::int64_t>(bounds_.memory_slack_ratio * static_cast<double>(start)));
  j.update({{"judged", true}, {"start_rss_bytes", start}, {"end_rss_bytes", end}, {"growth_bytes", end - start}});
  memory_.push_back(j);
  if (end - start > allowed) {
    add("memory", -1.0, -1,
        process + " grew from " + fixed(static_cast<double>(start) / 1048576.0, 1) + " MiB to " +
            fixed(static_cast<double>(end) / 1048576.0, 1) + " MiB (allowed " +
            fixed(static_cast<double>(allowed) / 1048576.0, 1) + " MiB)");
  }
}

void SoakChecker::run_failed(const std::string& error) { add("run", -1.0, -1, error); }

nlohmann::json SoakChecker::to_json() const {
  nlohmann::json v = nlohmann::json::array();
  for (const SoakViolation& x : violations_) {
    v.push_back({{"invariant", x.invariant}, {"time_s", x.time_s}, {"endcap", x.endcap}, {"detail", x.detail}});
  }
  const auto count = [this](const char* invariant) {
    return std::count_if(violations_.begin(), violations_.end(),
                         [invariant](const SoakViolation& x) { return x.invariant == invariant; });
  };
  const auto checked = [this](const char* invariant) {
    const auto it = checked_.find(invariant);
    return it == checked_.end() ? 0 : it->second;
  };
  nlohmann::json inv;
  inv["tension"] = {{"limit_n", bounds_.tension_limit_n}, {"max_n", max_tension_n_}, {"violations", count("tension")}};
  inv["estop"] = {{"sent", estops_},
                  {"acks_required", checked("estop")},
                  {"bound_s", bounds_.estop_s},
                  {"latency_p50_s", percentile(estop_latencies_s_, 0.5)},
                  {"latency_p99_s", percentile(estop_latencies_s_, 0.99)},
                  {"latency_max_s", percentile(estop_latencies_s_, 1.0)},
                  {"violations", count("estop")}};
  inv["table"] = {{"heartbeats", checked("table")},
                  {"policy_id", table_.first},
                  {"policy_version", table_.second},
                  {"violations", count("table")}};
  inv["host_loss"] = {{"losses", losses_}, {"cuts", cuts_}, {"violations", count("host_loss")}};
  inv["memory"] = {{"processes", memory_}, {"violations", count("memory")}};
  inv["run"] = {{"violations", count("run")}};
  return {{"invariants", inv}, {"violations", v}};
}

}  // namespace tensegrity::hil
