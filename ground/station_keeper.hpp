// SPDX-License-Identifier: Apache-2.0
// Keeps a long-lived ground station (the operator console's) joined. Fast DDS 2.9's
// security handshake with an end cap now and then stalls for good
// (docs/guide/security.md), also one way only: the station hears the end cap while
// what it writes never reaches it. A fresh participant handshakes afresh. An end cap
// counts as linked when it is heard and the station's writers reach its readers
// (Station::reached); when end caps it should be linked with stay unlinked and that
// set has not grown for `stall_s`, a
// second participant is made beside the first; it takes over once it hears all
// end caps, or after `trial_s` if it hears more than the first, and is dropped
// otherwise, after which the stall time doubles (an end cap that is switched off
// must not keep the console churning). Commands go on through the first station
// meanwhile, so a rejoin never leaves the console without its authenticated link.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>

#include "ground/station.hpp"

namespace tensegrity::ground {

class StationKeeper {
 public:
  struct Options {
    std::uint16_t expected = kAllEndcaps;
    double stall_s = 8.0;
    double trial_s = 20.0;
    double max_stall_s = 120.0;
    double fresh_s = Station::kHeardFreshS;  // an end cap is heard while its heartbeat is this recent
  };
  using MakeStation = std::function<std::unique_ptr<Station>()>;

  StationKeeper(MakeStation make, const Options& options);
  std::shared_ptr<Station> current() const;
  // Call every 0.1-1 s; `now_ns` on the host clock (Station::now_ns).
  void tick(std::int64_t now_ns);
  int rejoins() const;

  // The end caps of `expected` linked both ways: a heartbeat at most `fresh_s` old,
  // and the station's policy-table and command writers matched with their readers
  // (an estop would land). As a mask.
  static std::uint16_t linked(const Station& station, std::uint16_t expected, std::int64_t now_ns, double fresh_s);

 private:
  MakeStation make_;
  Options options_;
  mutable std::mutex mutex_;
  std::shared_ptr<Station> current_;
  std::unique_ptr<Station> candidate_;
  std::int64_t candidate_since_ns_ = 0;
  std::uint16_t last_heard_ = 0;
  std::int64_t last_growth_ns_ = 0;
  double stall_s_ = 0.0;
  int rejoins_ = 0;
};

}  // namespace tensegrity::ground
