// SPDX-License-Identifier: Apache-2.0
// The end cap's time-sync client as the node's threads share it: the node thread
// sends requests, settles them and says why it stays unsynchronized; Fast DDS's
// receive thread hands in replies and reads the estimate to judge commands. One
// mutex around TimeSyncClient (time_sync_client.hpp, which judges the replies).
#pragma once

#include <cstdint>
#include <mutex>

#include "firmware/comms/node/node_log.hpp"
#include "firmware/comms/logic/time_sync_client.hpp"
#include "firmware/hal/clock.hpp"

namespace tensegrity::fw::comms {

// The estimate at one moment, read once so that what is judged with it agrees.
struct SyncView {
  bool synced = false;
  std::int64_t offset_ns = 0;  // host minus local
  std::int64_t round_trip_ns = 0;
};

class SharedTimeSync {
 public:
  struct Request {
    std::int64_t t1_ns = 0;
    std::uint64_t nonce = 0;
  };

  SharedTimeSync(std::uint64_t nonce_seed, const NodeLog& log) : client_(nonce_seed), log_(log) {}

  // A request leaving now: t1 is read from `clock` under the lock, as late as
  // possible, since the round trip starts there.
  Request request(const Clock& clock);
  // One reply, stamped t4 on arrival; refusals are logged now and then.
  void on_reply(std::uint64_t nonce, std::int64_t t2_ns, std::int64_t t3_ns, std::int64_t t4_ns);
  void settle(std::int64_t now_ns);
  SyncView view() const;
  // While unsynchronized, one line saying why (a start is refused until then).
  void report_if_unsynced(std::uint32_t requests_sent) const;

 private:
  mutable std::mutex mutex_;
  TimeSyncClient client_;
  const NodeLog& log_;
};

}  // namespace tensegrity::fw::comms
