// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/logic/time_sync_client.hpp"

#include "firmware/comms/wire/wire_time.hpp"

namespace tensegrity::fw::comms {
namespace {

enum class Plausibility : std::uint8_t { ok, bad_stamp, hold_too_long, round_trip_too_long };

// Offset and round trip of one exchange, or why it is implausible. Every stamp
// is range-checked before it is subtracted.
Plausibility evaluate(const TimeSyncLimits& limits, std::int64_t t1, std::int64_t t2, std::int64_t t3, std::int64_t t4,
                      ClockSample& out) {
  auto local_ok = [](std::int64_t t) { return t >= -kMaxWireTimeNs && t <= kMaxWireTimeNs; };
  if (!valid_wire_time(t2) || !valid_wire_time(t3) || !local_ok(t1) || !local_ok(t4)) return Plausibility::bad_stamp;
  const std::int64_t hold = t3 - t2;
  const std::int64_t round_trip = (t4 - t1) - hold;
  if (hold < 0 || t4 < t1 || round_trip < 0) return Plausibility::bad_stamp;
  if (hold > limits.max_host_hold_ns) return Plausibility::hold_too_long;
  if (round_trip > limits.max_round_trip_ns) return Plausibility::round_trip_too_long;
  out = ClockSample{(t2 - t1) / 2 + (t3 - t4) / 2, round_trip, t4};
  return Plausibility::ok;
}

std::int64_t abs_diff(std::int64_t a, std::int64_t b) { return a > b ? a - b : b - a; }

// Two samples of the same offset agree within half of each round trip (each true
// offset lies within +-rtt/2 of its estimate), plus a tolerance for drift.
bool agree(const ClockSample& a, const ClockSample& b, std::int64_t tolerance_ns) {
  return abs_diff(a.offset_ns, b.offset_ns) <= a.round_trip_ns / 2 + b.round_trip_ns / 2 + tolerance_ns;
}

}  // namespace

TimeSyncClient::TimeSyncClient(std::uint64_t nonce_seed, const TimeSyncLimits& limits)
    : limits_(limits), state_(nonce_seed | 1U) {}

// xorshift64*: nonces need to be unpredictable to a late replayer and distinct,
// not cryptographic (an on-path attacker reads them; that is DDS Security's job).
std::uint64_t TimeSyncClient::next_nonce() {
  state_ ^= state_ >> 12;
  state_ ^= state_ << 25;
  state_ ^= state_ >> 27;
  return state_ * 0x2545F4914F6CDD1DULL;
}

std::uint64_t TimeSyncClient::start_request(std::int64_t t1_ns) {
  Pending& slot = pending_[next_slot_];
  settle_one(slot);
  next_slot_ = (next_slot_ + 1) % kOutstanding;
  slot = Pending{};
  slot.nonce = next_nonce();
  slot.t1_ns = t1_ns;
  slot.used = true;
  return slot.nonce;
}

TimeSyncVerdict TimeSyncClient::on_reply(std::uint64_t nonce, std::int64_t t2_ns, std::int64_t t3_ns,
                                         std::int64_t t4_ns) {
  Pending* p = nullptr;
  for (Pending& candidate : pending_) {
    if (candidate.used && candidate.nonce == nonce) p = &candidate;
  }
  if (p == nullptr) {
    ++counters_.unknown_nonce;
    return TimeSyncVerdict::unknown_nonce;
  }
  ClockSample sample;
  const Plausibility plausibility = evaluate(limits_, p->t1_ns, t2_ns, t3_ns, t4_ns, sample);
  if (plausibility != Plausibility::ok) {
    ++counters_.implausible;
    if (plausibility == Plausibility::round_trip_too_long) ++counters_.implausible_round_trip;
    if (plausibility == Plausibility::hold_too_long) ++counters_.implausible_hold;
    return TimeSyncVerdict::implausible;
  }
  if (p->answers++ == 0) {
    p->t2_ns = t2_ns;
    p->t3_ns = t3_ns;
    p->t4_ns = t4_ns;
    return TimeSyncVerdict::held;
  }
  ClockSample first;
  evaluate(limits_, p->t1_ns, p->t2_ns, p->t3_ns, p->t4_ns, first);
  if (!agree(first, sample, limits_.tolerance_ns)) p->conflicting = true;
  return TimeSyncVerdict::held;
}

void TimeSyncClient::settle(std::int64_t now_ns) {
  for (Pending& p : pending_) {
    // t1 is this end cap's own clock: no wire value in this subtraction.
    if (p.used && now_ns - p.t1_ns > limits_.settle_after_ns()) settle_one(p);
  }
}

void TimeSyncClient::settle_one(Pending& p) {
  if (!p.used) return;
  p.used = false;  // its nonce is spent: a later answer is unknown
  if (p.answers == 0) return;
  if (p.conflicting) {
    // Two sources disagree: the estimate came from one of them, so it is no
    // better than the other. Unsynchronized is the safe state (a start is refused;
    // stops, estops and clear-faults need no clock).
    ++counters_.conflicting;
    estimator_.reset();
    disagreeing_in_a_row_ = 0;
    return;
  }
  ClockSample s;
  evaluate(limits_, p.t1_ns, p.t2_ns, p.t3_ns, p.t4_ns, s);
  if (estimator_.synced() && !agree(estimator_.best(), s, limits_.tolerance_ns)) {
    // A new host, or a liar: only a run of samples that agree with each other
    // replaces the estimate.
    disagreeing_in_a_row_ =
        disagreeing_in_a_row_ > 0 && agree(disagreeing_, s, limits_.tolerance_ns) ? disagreeing_in_a_row_ + 1 : 1;
    disagreeing_ = s;
    if (disagreeing_in_a_row_ < kResyncAfter) {
      ++counters_.inconsistent;
      return;
    }
    estimator_.reset();
    ++counters_.resyncs;
  }
  disagreeing_in_a_row_ = 0;
  if (estimator_.add(p.t1_ns, p.t2_ns, p.t3_ns, p.t4_ns)) ++counters_.accepted;
}

}  // namespace tensegrity::fw::comms
