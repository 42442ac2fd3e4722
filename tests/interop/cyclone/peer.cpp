// SPDX-License-Identifier: Apache-2.0
#include "tests/interop/cyclone/peer.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

namespace tensegrity::interop {
namespace {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
std::int64_t to_ns(double s) { return static_cast<std::int64_t>(s * 1e9); }
double ms(std::int64_t ns) { return static_cast<double>(ns) / 1e6; }

// Takes every sample `reader` holds into `on_sample`. Telemetry_ and PolicyAck_
// have no pointers (bounded strings are char arrays), so the samples can live on
// the stack and Cyclone deserializes into them.
template <typename T, typename F>
void drain(dds_entity_t reader, F&& on_sample) {
  constexpr int kBatch = 32;
  T samples[kBatch];
  void* ptrs[kBatch];
  dds_sample_info_t infos[kBatch];
  for (int i = 0; i < kBatch; ++i) ptrs[i] = &samples[i];
  for (;;) {
    const dds_return_t n = dds_take(reader, ptrs, infos, kBatch, kBatch);
    if (n <= 0) return;
    for (int i = 0; i < n; ++i) {
      if (infos[i].valid_data) on_sample(samples[i]);
    }
    if (n < kBatch) return;
  }
}

}  // namespace

Peer::Peer(int domain, std::uint16_t mask) : participant_(domain), mask_(mask) {
  telemetry_ = participant_.reader(kTelemetryTopic);
  acks_ = participant_.reader(kPolicyAckTopic);
  tables_ = participant_.writer(kPolicyTableTopic);
  waitset_ = dds_create_waitset(participant_.handle());
  for (const dds_entity_t r : {telemetry_, acks_}) {
    const dds_entity_t cond = dds_create_readcondition(r, DDS_ANY_STATE);
    if (waitset_ < 0 || cond < 0 || dds_waitset_attach(waitset_, cond, r) != DDS_RETCODE_OK) {
      throw CycloneError("cannot set up the waitset");
    }
  }
  for (const CycloneTopic* t : {&kTelemetryTopic, &kPolicyAckTopic, &kPolicyTableTopic}) {
    std::printf("TOPIC name=%s type=%s\n", t->name, t->descriptor->m_typename);
  }
  std::printf("PARTITION reads=%s\n", kEndcapReportsPartition);
  started_ns_ = now_ns();
}

// Phase 1: every addressed end cap's telemetry arrives (discovery included).
bool Peer::wait_for_telemetry(double timeout_s) {
  const std::int64_t deadline = now_ns() + to_ns(timeout_s);
  while (!stats_.all_seen(mask_) && now_ns() < deadline) poll(deadline);
  bool ok = true;
  for (int e = 0; e < kEndcapCount; ++e) {
    if (!addressed(e)) continue;
    if (stats_[e].seen) {
      std::printf("SEEN endcap=%d after_ms=%.1f\n", e, ms(stats_[e].first_ns - started_ns_));
    } else {
      std::printf("MISSING endcap=%d: no telemetry within %.1f s\n", e, timeout_s);
      ok = false;
    }
  }
  return ok;
}

// Phase 2: count samples for `seconds`; the rate is what this peer receives.
bool Peer::listen(double seconds) {
  std::array<std::uint64_t, kEndcapCount> samples0{}, lost0{};
  for (int e = 0; e < kEndcapCount; ++e) {
    samples0[static_cast<std::size_t>(e)] = stats_[e].samples;
    lost0[static_cast<std::size_t>(e)] = stats_[e].lost;
  }
  const std::int64_t t0 = now_ns();
  const std::int64_t end = t0 + to_ns(seconds);
  while (now_ns() < end) poll(end);
  const double dt = static_cast<double>(now_ns() - t0) / 1e9;
  double total = 0.0, lowest = 1e9;
  std::uint64_t lost = 0;
  for (int e = 0; e < kEndcapCount; ++e) {
    if (!addressed(e)) continue;
    const auto i = static_cast<std::size_t>(e);
    const double rate = static_cast<double>(stats_[e].samples - samples0[i]) / dt;
    total += rate;
    lowest = std::min(lowest, rate);
    lost += stats_[e].lost - lost0[i];
    std::printf("TELEMETRY endcap=%d samples=%llu rate_hz=%.1f lost=%llu mode=%u\n", e,
                static_cast<unsigned long long>(stats_[e].samples - samples0[i]), rate,
                static_cast<unsigned long long>(stats_[e].lost - lost0[i]), unsigned{stats_[e].mode});
  }
  std::printf("MEASURE cyclone_telemetry total_hz=%.1f lowest_endcap_hz=%.1f lost=%llu refused=%llu over_s=%.2f\n",
              total, lowest, static_cast<unsigned long long>(lost), static_cast<unsigned long long>(stats_.refused()),
              dt);
  if (stats_.refused() > 0) std::printf("REFUSED last: %s\n", stats_.last_refusal().c_str());
  return lowest > 0.0 && stats_.refused() == 0;
}

// Phase 3 (optional): one table with a wrong checksum, which must come back
// rejected with reason bad_checksum (8): the end cap checks what we send.
bool Peer::upload_bad_checksum(const PolicyParams& params, int endcap, double timeout_s) {
  PolicyTableOut table(params, endcap, sequence_base_ - 1);
  table.corrupt_checksum();
  std::map<int, PolicyTableOut*> one{{endcap, &table}};
  const auto acks = exchange(one, timeout_s);
  const auto it = acks.find(endcap);
  if (it == acks.end()) return false;
  return !it->second.accepted && it->second.reason == 8;
}

// Phase 3: a table per end cap, every one acknowledged as accepted; the time
// from the first write to the last ack in `latency_ms`.
bool Peer::upload(const PolicyParams& params, double timeout_s, double& latency_ms) {
  sequence_base_ += 16;  // a fresh sequence per upload: an old ack never matches
  std::map<int, PolicyTableOut> tables;
  std::map<int, PolicyTableOut*> out;
  for (int e = 0; e < kEndcapCount; ++e) {
    if (!addressed(e)) continue;
    tables.emplace(e, PolicyTableOut(params, e, sequence_base_ + static_cast<std::uint32_t>(e)));
    out[e] = &tables.at(e);
  }
  const std::int64_t t0 = now_ns();
  const auto acks = exchange(out, timeout_s);
  latency_ms = ms(last_ack_ns_ - t0);
  bool ok = acks.size() == out.size();
  for (const auto& [e, ack] : acks) ok = ok && ack.accepted && ack.reason == 0;
  return ok;
}

// The ack says the loop took the table; the telemetry says it runs it.
bool Peer::wait_active(const PolicyParams& params, double timeout_s) {
  const std::int64_t deadline = now_ns() + to_ns(timeout_s);
  auto active = [&](int e) {
    return stats_[e].active_policy_id == params.policy_id && stats_[e].active_policy_version == params.policy_version;
  };
  auto all_active = [&] {
    for (int e = 0; e < kEndcapCount; ++e) {
      if (addressed(e) && !active(e)) return false;
    }
    return true;
  };
  while (!all_active() && now_ns() < deadline) poll(deadline);
  for (int e = 0; e < kEndcapCount; ++e) {
    if (!addressed(e)) continue;
    std::printf("ACTIVE endcap=%d policy=%s v%u%s\n", e, stats_[e].active_policy_id.c_str(),
                stats_[e].active_policy_version, active(e) ? "" : " (not the uploaded one)");
  }
  return all_active();
}

// Waits (at most until `deadline`, at most 100 ms) for data, then takes it all.
void Peer::poll(std::int64_t deadline) {
  const std::int64_t wait = std::min<std::int64_t>(std::max<std::int64_t>(deadline - now_ns(), 0), 100'000'000);
  dds_waitset_wait(waitset_, nullptr, 0, wait);
  drain<TelemetryC>(telemetry_, [this](const TelemetryC& t) { stats_.add(t, now_ns()); });
  drain<PolicyAckC>(acks_, [this](const PolicyAckC& a) {
    const std::string why = check_ack(a);
    if (!why.empty()) {
      std::printf("REFUSED ack: %s\n", why.c_str());
      return;
    }
    acks_in_.push_back(a);
  });
}

// Writes each table, re-sends the unanswered ones every second (same upload
// sequence: an end cap answers a retry with its first answer), and returns the
// acks that answer them. Acks of other uploads (history) do not match a sequence.
std::map<int, Peer::Ack> Peer::exchange(const std::map<int, PolicyTableOut*>& tables, double timeout_s) {
  std::map<int, Ack> got;
  const std::int64_t deadline = now_ns() + to_ns(timeout_s);
  // Transient-local would deliver to a late reader too; waiting for a match
  // just keeps the first write from being a retry.
  while (matched_readers(tables_) == 0 && now_ns() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  std::int64_t next_send = 0;
  while (got.size() < tables.size() && now_ns() < deadline) {
    if (now_ns() >= next_send) {
      for (const auto& [e, t] : tables) {
        if (got.count(e) != 0) continue;
        const dds_return_t rc = dds_write(tables_, &t->message());
        if (rc != DDS_RETCODE_OK) std::printf("WRITE endcap=%d failed: %s\n", e, dds_strretcode(rc));
      }
      next_send = now_ns() + 1'000'000'000;
    }
    poll(std::min(deadline, next_send));
    for (const PolicyAckC& a : acks_in_) {
      const auto it = tables.find(a.endcap_id);
      if (it == tables.end() || a.upload_sequence != it->second->message().upload_sequence) continue;
      if (got.count(a.endcap_id) != 0) continue;
      got[a.endcap_id] = Ack{a.accepted, a.reason};
      last_ack_ns_ = now_ns();
      if (quiet_ && a.accepted) continue;
      std::printf("ACK endcap=%d seq=%u accepted=%d reason=%u text='%s' active=%s v%u checksum=0x%08x\n", a.endcap_id,
                  a.upload_sequence, a.accepted ? 1 : 0, unsigned{a.reason}, a.reason_text, a.active_policy_id,
                  a.active_policy_version, a.active_checksum);
    }
    acks_in_.clear();
  }
  for (const auto& [e, t] : tables) {
    if (got.count(e) == 0) std::printf("NO_ACK endcap=%d within %.1f s\n", e, timeout_s);
  }
  return got;
}

}  // namespace tensegrity::interop
