// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/mpi_evaluator.hpp"

#include <algorithm>
#include <thread>

#include "sim/evolve/mpi_launch.hpp"

namespace tensegrity::sim::evolve {
namespace {

using Clock = std::chrono::steady_clock;

std::string who(const RankLoad& r) { return "rank " + std::to_string(r.rank) + " (" + r.host + ")"; }

bool timed_out(Clock::time_point since, double timeout_s) {
  return timeout_s > 0.0 && std::chrono::duration<double>(Clock::now() - since).count() > timeout_s;
}

}  // namespace

MpiEvaluator::MpiEvaluator(MpiSession& session, const wire::Setup& setup, TeamFunction local,
                           const MpiEvaluatorOptions& options)
    : session_(session), options_(options) {
  if (session_.rank() != 0) throw std::logic_error("MpiEvaluator runs on rank 0 only");
  if (options_.local_threads > 0) local_ = std::make_unique<TeamWorkers>(std::move(local), options_.local_threads);
  ranks_.resize(static_cast<std::size_t>(session_.size()));
  ranks_[0] = RankLoad{0, session_.host(), options_.local_threads, 0, build_fingerprint()};

  const wire::Bytes bytes = wire::encode(setup);
  for (int r = 1; r < session_.size(); ++r) session_.send(r, wire::Tag::setup, bytes, options_.timeout_s);
  // Every answer first, then every complaint at once.
  std::vector<std::string> errors;
  int answered = 0;
  const auto sent = Clock::now();
  PollWait wait;
  std::vector<bool> seen(ranks_.size(), false);
  while (answered < session_.size() - 1) {
    auto message = session_.try_receive();
    if (!message) {
      if (timed_out(sent, options_.timeout_s)) {
        std::string silent;
        for (int r = 1; r < session_.size(); ++r) {
          if (!seen[static_cast<std::size_t>(r)]) silent += " " + std::to_string(r);
        }
        throw MpiFailure("no answer to the setup within " + std::to_string(static_cast<long long>(options_.timeout_s)) +
                         " s from rank(s)" + silent);
      }
      std::this_thread::sleep_for(wait.next(false));
      continue;
    }
    wait.next(true);
    const auto r = static_cast<std::size_t>(message->from);
    if (message->tag != wire::Tag::hello || r == 0 || seen[r]) {
      throw MpiFailure("rank " + std::to_string(message->from) + " sent an unexpected " +
                       wire::to_string(message->tag) + " message while rank 0 waited for answers to the setup");
    }
    const wire::Hello hello = wire::decode_hello(message->bytes);
    seen[r] = true;
    ++answered;
    RankLoad& rank = ranks_[r];
    rank = RankLoad{message->from, hello.host, hello.threads, 0, hello.build};
    if (hello.protocol != wire::kProtocol) {
      errors.push_back(who(rank) + " speaks protocol " + std::to_string(hello.protocol) + ", rank 0 " +
                       std::to_string(wire::kProtocol) + " (run the same tensegrity build on every machine)");
    } else if (!hello.error.empty()) {
      errors.push_back(who(rank) + ": " + hello.error);
    } else if (hello.threads < 1) {
      errors.push_back(who(rank) + " reports " + std::to_string(hello.threads) + " threads");
    } else if (hello.build != ranks_[0].build) {
      warnings_.push_back(who(rank) + " runs another build (" + hello.build + "; rank 0: " + ranks_[0].build +
                          "): its scores may differ in the last bits from a run on rank 0's machine alone");
    }
  }
  if (!errors.empty()) {
    std::string text = "setting up the MPI ranks failed:";
    for (const auto& e : errors) text += "\n  " + e;
    throw std::runtime_error(text);
  }
  if (threads() < 1) throw std::runtime_error("no rank evaluates teams: rank 0 has no threads and no other rank runs");
}

MpiEvaluator::~MpiEvaluator() = default;

int MpiEvaluator::threads() const {
  int total = 0;
  for (const auto& r : ranks_) total += r.threads;
  return total;
}

void MpiEvaluator::check_timeouts(const std::vector<std::vector<Sent>>& outstanding) const {
  for (std::size_t r = 1; r < outstanding.size(); ++r) {
    if (outstanding[r].empty()) continue;
    const auto oldest = std::min_element(outstanding[r].begin(), outstanding[r].end(),
                                         [](const Sent& a, const Sent& b) { return a.at < b.at; });
    if (timed_out(oldest->at, options_.timeout_s)) {
      throw MpiFailure(who(ranks_[r]) + " has returned nothing for " +
                       std::to_string(static_cast<long long>(options_.timeout_s)) + " s while holding " +
                       std::to_string(outstanding[r].size()) +
                       " team(s): it is stopped, hung or unreachable (--mpi-timeout sets this limit)");
    }
  }
}

std::vector<TeamResult> MpiEvaluator::evaluate(std::span<const Team> teams) {
  ++batch_;
  const std::size_t count = teams.size();
  std::vector<TeamResult> results(count);
  std::vector<std::vector<Sent>> outstanding(ranks_.size());
  std::size_t next = 0;      // the next team to hand out
  std::size_t finished = 0;  // teams whose result is in
  std::string error;         // the first evaluation that threw
  PollWait wait;

  auto take = [&](std::size_t index, const TeamResult& result, const std::string& failure, RankLoad& rank) {
    results[index] = result;
    ++finished;
    ++rank.teams;
    if (!failure.empty() && error.empty()) error = who(rank) + ": " + failure;
  };

  for (;;) {
    // Hand out: every idle thread of every rank gets the next team. After an error
    // nothing more goes out; what is out is still awaited.
    if (error.empty()) {
      while (local_ && next < count && local_->in_flight() < static_cast<std::size_t>(options_.local_threads)) {
        local_->submit(next, teams[next]);
        ++next;
      }
      for (std::size_t r = 1; r < ranks_.size(); ++r) {
        while (next < count && outstanding[r].size() < static_cast<std::size_t>(ranks_[r].threads)) {
          session_.send(static_cast<int>(r), wire::Tag::job, wire::encode(wire::Job{batch_, next, teams[next]}),
                        options_.timeout_s);
          outstanding[r].push_back(Sent{next, Clock::now()});
          ++next;
        }
      }
    }
    if (finished == next && (next == count || !error.empty())) break;

    bool activity = false;
    while (auto message = session_.try_receive()) {
      activity = true;
      const auto r = static_cast<std::size_t>(message->from);
      if (message->tag != wire::Tag::result || r == 0) {
        throw MpiFailure("rank " + std::to_string(message->from) + " sent an unexpected " +
                         wire::to_string(message->tag) + " message during an evaluation");
      }
      const wire::Result result = wire::decode_result(message->bytes);
      auto& held = outstanding[r];
      const auto it = std::find_if(held.begin(), held.end(), [&](const Sent& s) { return s.index == result.index; });
      if (result.batch != batch_ || it == held.end()) {
        throw MpiFailure(who(ranks_[r]) + " returned team " + std::to_string(result.index) + " of batch " +
                         std::to_string(result.batch) + ", which it was not given");
      }
      held.erase(it);
      take(static_cast<std::size_t>(result.index), result.result, result.error, ranks_[r]);
    }
    const auto pause = wait.next(activity);
    if (local_) {
      const auto done = local_->collect(pause);
      if (!done.empty()) wait.next(true);
      for (const auto& f : done) take(static_cast<std::size_t>(f.job), f.result, f.error, ranks_[0]);
    } else if (pause.count() > 0) {
      std::this_thread::sleep_for(pause);
    }
    check_timeouts(outstanding);
  }
  if (!error.empty()) throw std::runtime_error(error);
  return results;
}

}  // namespace tensegrity::sim::evolve
