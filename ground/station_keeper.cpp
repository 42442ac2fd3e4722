// SPDX-License-Identifier: Apache-2.0
#include "ground/station_keeper.hpp"

#include <algorithm>
#include <bit>
#include <stdexcept>
#include <utility>

namespace tensegrity::ground {

StationKeeper::StationKeeper(MakeStation make, const Options& options)
    : make_(std::move(make)), options_(options), stall_s_(options.stall_s) {
  if (!make_) throw std::invalid_argument("station keeper: no way to make a station");
  if (!(options.stall_s > 0.0) || !(options.trial_s > 0.0) || !(options.fresh_s > 0.0)) {
    throw std::invalid_argument("station keeper: stall, trial and freshness times must be > 0 s");
  }
  current_ = make_();
  last_growth_ns_ = Station::now_ns();
}

std::shared_ptr<Station> StationKeeper::current() const {
  std::lock_guard lock(mutex_);
  return current_;
}

int StationKeeper::rejoins() const {
  std::lock_guard lock(mutex_);
  return rejoins_;
}

std::uint16_t StationKeeper::linked(const Station& station, std::uint16_t expected, std::int64_t now_ns,
                                    double fresh_s) {
  return static_cast<std::uint16_t>(station.heard(now_ns, fresh_s) & station.reached() & expected);
}

void StationKeeper::tick(std::int64_t now_ns) {
  // Stations leaving are destroyed after the lock is released (a participant takes
  // a while to close), so that current() never waits for one.
  std::shared_ptr<Station> leaving;
  std::unique_ptr<Station> dropped;
  std::unique_lock lock(mutex_);
  const std::uint16_t now_heard = linked(*current_, options_.expected, now_ns, options_.fresh_s);
  if ((now_heard & ~last_heard_) != 0) last_growth_ns_ = now_ns;
  last_heard_ = now_heard;
  if (candidate_) {
    // A candidate takes over when it hears every end cap, or at the end of its
    // trial if it hears more than the current station (not before: one still
    // discovering would win with a partial set).
    const std::uint16_t got = linked(*candidate_, options_.expected, now_ns, options_.fresh_s);
    const bool trial_over = now_ns - candidate_since_ns_ > static_cast<std::int64_t>(options_.trial_s * 1e9);
    if (got == options_.expected || (trial_over && std::popcount(got) > std::popcount(now_heard))) {
      leaving = std::exchange(current_, std::shared_ptr<Station>(std::move(candidate_)));
      ++rejoins_;
      stall_s_ = options_.stall_s;
      last_heard_ = got;
      last_growth_ns_ = now_ns;
    } else if (trial_over) {
      dropped = std::move(candidate_);
      stall_s_ = std::min(2.0 * stall_s_, options_.max_stall_s);
      last_growth_ns_ = now_ns;
    }
    return;  // `lock` is released before `leaving` and `dropped` go
  }
  const bool stalled =
      now_heard != options_.expected && now_ns - last_growth_ns_ > static_cast<std::int64_t>(stall_s_ * 1e9);
  if (!stalled) return;
  lock.unlock();  // making a participant takes a while; current() must not wait for it
  std::unique_ptr<Station> fresh = make_();
  lock.lock();
  candidate_ = std::move(fresh);
  candidate_since_ns_ = Station::now_ns();
}

}  // namespace tensegrity::ground
