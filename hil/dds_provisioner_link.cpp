// SPDX-License-Identifier: Apache-2.0
// DdsProvisioner, step 1: every end cap on the link with a synchronized clock, and
// how long that took (the link's timing, for `bench hil`); and during a real-time
// run, the host's view of that link.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "ground/station_keeper.hpp"
#include "hil/dds_provisioner.hpp"
#include "hil/hil_error.hpp"

namespace tensegrity::hil {

namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;

std::string list(const std::vector<int>& ids) {
  std::string s;
  for (int i : ids) s += (s.empty() ? "" : ", ") + std::to_string(i);
  return s;
}

}  // namespace

LinkTiming DdsProvisioner::link_timing() const {
  std::lock_guard lock(mutex_);
  return timing_;
}

// Fast DDS 2.9's PKI-DH handshake between two processes now and then never
// completes (docs/guide/security.md: with two secured HIL runs at once, 2 of 8 left one end
// cap unheard for 40 s; alone, 2 of 10 stalled and were recovered by this). A new
// ground participant (a new GUID) authenticates afresh; so when the set of end caps
// heard stops growing for kRejoinAfterNs short of all (or all heard but not every
// clock synchronized), the station joins again.
bool DdsProvisioner::wait_or_rejoin(std::uint16_t mask, std::int64_t deadline_ns) {
  constexpr std::int64_t kRejoinAfterNs = 8 * kNsPerS;
  auto heard = [this, mask] {
    int n = 0;
    const auto status = station_->snapshot();
    for (int e = 0; e < robot_.endcap_count(); ++e) n += ((mask >> e) & 1U) != 0 && status[e].seen ? 1 : 0;
    return n;
  };
  int last = -1;
  std::int64_t grew_ns = ground::Station::now_ns();
  while (true) {
    const std::int64_t now = ground::Station::now_ns();
    const std::int64_t until = std::min(deadline_ns, now + kNsPerS);
    if (station_->wait_for_endcaps(mask, true, until)) return true;
    const std::int64_t after = ground::Station::now_ns();
    if (after >= deadline_ns) return false;
    const int n = heard();
    if (n != last) {
      last = n;
      grew_ns = after;
    } else if (after - grew_ns > kRejoinAfterNs && n > 0 && !station_options_.enclave_dir.empty()) {
      note("dds: " + std::to_string(n) +
           " end caps heard, no more for 8 s: the ground station joins again "
           "(a DDS Security handshake that never completed)");
      station_.reset();
      station_ = std::make_unique<ground::Station>(station_options_);
      last = -1;
      grew_ns = ground::Station::now_ns();
    }
  }
}

void DdsProvisioner::await_endcaps(std::uint16_t mask, std::int64_t deadline_ns) {
  if (wait_or_rejoin(mask, deadline_ns)) return;
  std::vector<int> missing, unsynced;
  const auto status = station_->snapshot();
  for (int e = 0; e < robot_.endcap_count(); ++e) {
    if (!status[e].seen) {
      missing.push_back(e);
    } else if (!status[e].heartbeat.clock_synced()) {
      unsynced.push_back(e);
    }
  }
  char within[64];
  std::snprintf(within, sizeof within, "DDS: within %.1f s", config_.discovery_timeout_s);
  std::string why = within;
  if (!missing.empty()) why += ", no heartbeat from end cap(s) " + list(missing);
  if (!unsynced.empty()) why += ", clock not synchronized on end cap(s) " + list(unsynced);
  throw LinkDownError(why + " (see their logs)");
}

// The end cap's heartbeat comes at 5 Hz; the operator console's station keeper calls an
// end cap unheard after its fresh_s (2 s, the end caps' own host window), and so does this.
void DdsProvisioner::watch_link(const std::array<ground::EndcapStatus, ground::kEndcapCount>& status,
                                std::int64_t now_ns) {
  static const auto kUnheardAfterNs =
      static_cast<std::int64_t>(ground::StationKeeper::Options{}.fresh_s * static_cast<double>(kNsPerS));
  const auto run_s = [this](std::int64_t host_ns) { return static_cast<double>(host_ns - run_begun_ns_) * 1e-9; };
  for (std::size_t e = 0; e < unheard_since_ns_.size() && e < status.size(); ++e) {
    const ground::EndcapStatus& s = status[e];
    const std::int64_t last = s.seen ? s.heartbeat_host_ns : run_begun_ns_;
    char line[160];
    if (unheard_since_ns_[e] == 0 && now_ns - std::max(last, run_begun_ns_) > kUnheardAfterNs) {
      unheard_since_ns_[e] = std::max(last, run_begun_ns_);
      std::snprintf(line, sizeof line, "dds: end cap %zu unheard by the host since %.1f s into the run", e,
                    run_s(unheard_since_ns_[e]));
      note(line);
    } else if (unheard_since_ns_[e] != 0 && last > unheard_since_ns_[e]) {
      const double spell_s = static_cast<double>(last - unheard_since_ns_[e]) * 1e-9;
      std::snprintf(line, sizeof line, "dds: end cap %zu heard again at %.1f s into the run, after %.1f s unheard", e,
                    run_s(last), spell_s);
      unheard_since_ns_[e] = 0;
      note(line);
      std::lock_guard lock(mutex_);
      HostHearing& h = hearing_.at(e);
      ++h.unheard;
      h.unheard_s += spell_s;
      h.longest_unheard_s = std::max(h.longest_unheard_s, spell_s);
    }
  }
}

// After end_run: the supervisor is gone, and a spell still open lasts to the run's end.
std::vector<HostHearing> DdsProvisioner::host_hearing() const {
  std::lock_guard lock(mutex_);
  std::vector<HostHearing> out = hearing_;
  for (std::size_t e = 0; e < out.size() && e < unheard_since_ns_.size(); ++e) {
    if (unheard_since_ns_[e] == 0 || run_ended_ns_ == 0) continue;
    const double spell_s = static_cast<double>(run_ended_ns_ - unheard_since_ns_[e]) * 1e-9;
    ++out[e].unheard;
    out[e].unheard_s += spell_s;
    out[e].longest_unheard_s = std::max(out[e].longest_unheard_s, spell_s);
  }
  return out;
}

}  // namespace tensegrity::hil
