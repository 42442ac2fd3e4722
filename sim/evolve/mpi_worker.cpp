// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/mpi_worker.hpp"

#include <memory>
#include <thread>
#include <unordered_map>

#include "sim/evolve/mpi_launch.hpp"
#include "sim/evolve/team_workers.hpp"

namespace tensegrity::sim::evolve {
namespace {

struct JobKey {
  std::uint64_t batch = 0;
  std::uint64_t index = 0;
};

}  // namespace

void serve_evaluations(MpiSession& session, int threads, const TeamFunctionFactory& factory) {
  const std::string me = "rank " + std::to_string(session.rank());
  std::unique_ptr<TeamWorkers> workers;
  std::unordered_map<std::uint64_t, JobKey> jobs;  // TeamWorkers' job id -> rank 0's names
  std::uint64_t next_id = 0;
  PollWait wait;
  for (;;) {
    bool activity = false;
    while (auto message = session.try_receive()) {
      activity = true;
      if (message->from != 0) {
        throw MpiFailure(me + ": unexpected " + std::string(wire::to_string(message->tag)) + " message from rank " +
                         std::to_string(message->from));
      }
      switch (message->tag) {
        case wire::Tag::stop: return;  // ~TeamWorkers waits for the teams being evaluated
        case wire::Tag::setup: {
          if (!jobs.empty()) throw MpiFailure(me + ": a new setup arrived while teams were being evaluated");
          workers.reset();
          wire::Hello hello{wire::kProtocol, threads, session.host(), build_fingerprint(), {}};
          try {
            const wire::Setup setup = wire::decode_setup(message->bytes);
            if (setup.protocol != wire::kProtocol) {
              throw wire::WireError("rank 0 speaks protocol " + std::to_string(setup.protocol) + ", this rank " +
                                    std::to_string(wire::kProtocol));
            }
            workers = std::make_unique<TeamWorkers>(factory(setup), threads);
          } catch (const std::exception& e) {
            hello.error = e.what();
          }
          session.send(0, wire::Tag::hello, wire::encode(hello), 0.0);
          break;
        }
        case wire::Tag::job: {
          if (!workers) throw MpiFailure(me + ": a team arrived without a working setup");
          wire::Job job = wire::decode_job(message->bytes);
          const std::uint64_t id = next_id++;
          jobs.emplace(id, JobKey{job.batch, job.index});
          workers->submit(id, std::move(job.team));
          break;
        }
        default:
          throw MpiFailure(me + ": unexpected " + std::string(wire::to_string(message->tag)) + " message from rank 0");
      }
    }
    const auto pause = wait.next(activity);
    if (!workers) {
      if (pause.count() > 0) std::this_thread::sleep_for(pause);
      continue;
    }
    const auto done = workers->collect(pause);
    if (!done.empty()) wait.next(true);
    for (const auto& f : done) {
      const auto it = jobs.find(f.job);
      const wire::Result result{it->second.batch, it->second.index, f.result, f.error};
      jobs.erase(it);
      session.send(0, wire::Tag::result, wire::encode(result), 0.0);
    }
  }
}

}  // namespace tensegrity::sim::evolve
