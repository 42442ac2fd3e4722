// SPDX-License-Identifier: Apache-2.0
// The end cap's side of a stalled link, decided. Fast DDS 2.9's security handshake
// now and then stalls for good in one direction (docs/guide/security.md): an end cap
// then hears the host's heartbeat while the host never hears its own, and no new
// host participant clears it. The host's heartbeat names the end caps it hears; an
// end cap that hears hosts which hear other end caps but not itself, for
// unheard_rejoin_s, makes a new participant, as the host's stations do on their side
// (ground/station_keeper.hpp). A host that hears nobody is left to mend its own
// side: the fault is then not this end cap's to fix, and a one-shot tool that has
// not heard anyone yet must not make twelve end caps churn.
//
// This class only decides (node thread, node clock); the node makes and closes the
// participants. The new one is made before the old one goes: the stall may be one
// way only, so the old one can still carry orders in until the link works both
// ways on the new one.
#pragma once

#include <atomic>
#include <cstdint>

#include "firmware/comms/node/node_log.hpp"

namespace tensegrity::fw::comms {

class RejoinWatch {
 public:
  static constexpr double kMaxBackoff = 8.0;                         // the wait grows to at most 8 x unheard_rejoin_s
  static constexpr std::int64_t kHostWindowNs = 2'000'000'000;       // a host's heard mask covers its last 2 s
  static constexpr std::int64_t kRemakeRetryNs = 1'000'000'000;      // making a participant failed: again after,
  static constexpr std::int64_t kRemakeRetryMaxNs = 60'000'000'000;  // doubling up to this

  // What the node watches of the host and its loop, as of this pass.
  struct Host {
    bool seen = false;
    bool lost = false;
    bool loop_stalled = false;  // the heartbeat is withheld on purpose
  };
  struct Step {
    bool retire_old = false;  // the previous participant may close now
    bool rejoin = false;      // make a new participant now
  };

  // unheard_rejoin_s 0: never rejoin. `endcap_id` in 0..15.
  RejoinWatch(int endcap_id, double unheard_rejoin_s, const NodeLog& log);

  void start(std::int64_t now_ns);
  // A host heartbeat naming `heard_endcaps`; `fresh_host`: none was heard before or
  // the host was lost; `on_current`: taken by the participant of the moment.
  void heard(std::uint16_t heard_endcaps, std::int64_t now_ns, bool fresh_host, bool on_current);
  Step poll(std::int64_t now_ns, const Host& host, bool overlapping);
  // The host was just lost, its last heartbeat at `last_heard_ns`: true when that
  // was this participant's doing and a new one is due.
  bool host_lost(std::int64_t last_heard_ns, bool loop_stalled);
  // The node made a new participant at `made_ns`, or failed to (`what`) and
  // finished trying at `now_ns`.
  void made(std::int64_t made_ns);
  void failed(std::int64_t now_ns, const char* what);

  bool pending() const { return remake_pending_; }  // a failed remake is retried at next_attempt_ns()
  std::int64_t next_attempt_ns() const { return next_remake_ns_; }
  double wait_s() const { return wait_s_; }
  std::uint64_t rejoins() const noexcept { return rejoins_.load(std::memory_order_relaxed); }

 private:
  bool rejoin_unheard(const char* what, std::int64_t unheard_ns, const char* then);

  std::uint16_t self_bit_;
  double unheard_rejoin_s_;
  const NodeLog& log_;
  std::int64_t hearing_since_ns_ = 0;       // host heartbeats arriving without a loss since
  std::int64_t named_ns_ = 0;               // a host heartbeat last named this end cap
  std::int64_t others_named_ns_ = 0;        // ... named another end cap
  std::int64_t others_named_since_ns_ = 0;  // ... and had, without a gap, since
  std::int64_t participant_since_ns_ = 0;   // the current participant was made
  bool current_hears_host_ = false;         // the current participant has taken a host heartbeat
  bool remake_pending_ = false;             // making a new participant failed ...
  std::int64_t next_remake_ns_ = 0;         // ... and is tried again then,
  std::int64_t remake_retry_ns_ = 0;        // ... after this (doubling)
  std::uint32_t remake_failures_ = 0;
  double wait_s_ = 0.0;  // doubles while rejoins go unanswered
  std::atomic<std::uint64_t> rejoins_{0};
};

}  // namespace tensegrity::fw::comms
