// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/node/shared_time_sync.hpp"

namespace tensegrity::fw::comms {

SharedTimeSync::Request SharedTimeSync::request(const Clock& clock) {
  std::lock_guard lock(mutex_);
  const std::int64_t t1 = clock.now_ns();
  return {t1, client_.start_request(t1)};
}

void SharedTimeSync::on_reply(std::uint64_t nonce, std::int64_t t2_ns, std::int64_t t3_ns, std::int64_t t4_ns) {
  std::uint64_t refused = 0;
  std::uint64_t unknown = 0;
  {
    std::lock_guard lock(mutex_);
    const TimeSyncVerdict verdict = client_.on_reply(nonce, t2_ns, t3_ns, t4_ns);
    if (verdict == TimeSyncVerdict::implausible) refused = client_.counters().implausible;
    if (verdict == TimeSyncVerdict::unknown_nonce) unknown = client_.counters().unknown_nonce;
  }
  // Both say why an end cap stays unsynchronized ("see their logs").
  if (refused % 100 == 1) {
    log_("refused an implausible time-sync reply (%llu so far)", static_cast<unsigned long long>(refused));
  }
  if (unknown % 100 == 1) {
    log_("ignored a time-sync reply to no open request: late or replayed (%llu so far)",
         static_cast<unsigned long long>(unknown));
  }
}

void SharedTimeSync::settle(std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  client_.settle(now_ns);
}

SyncView SharedTimeSync::view() const {
  std::lock_guard lock(mutex_);
  const ClockSample best = client_.estimator().best();
  return {client_.estimator().synced(), best.offset_ns, best.round_trip_ns};
}

void SharedTimeSync::report_if_unsynced(std::uint32_t requests_sent) const {
  TimeSyncCounters c;
  {
    std::lock_guard lock(mutex_);
    if (client_.estimator().synced()) return;
    c = client_.counters();
  }
  using ull = unsigned long long;
  log_(
      "time sync: not synchronized after %u requests; replies accepted %llu, late or replayed %llu, implausible %llu "
      "(round trip > limit %llu, host hold > limit %llu), conflicting %llu",
      requests_sent, static_cast<ull>(c.accepted), static_cast<ull>(c.unknown_nonce), static_cast<ull>(c.implausible),
      static_cast<ull>(c.implausible_round_trip), static_cast<ull>(c.implausible_hold),
      static_cast<ull>(c.conflicting));
}

}  // namespace tensegrity::fw::comms
