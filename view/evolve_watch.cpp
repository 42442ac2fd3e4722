// SPDX-License-Identifier: Apache-2.0
#include "view/evolve_watch.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "sim/model/core_controller.hpp"
#include "sim/model/episode.hpp"
#include "sim/evolve/checkpoint.hpp"
#include "sim/evolve/episode_evaluator.hpp"
#include "robot/robot.hpp"
#include "view/replay_sink.hpp"
#include "view/robot_json.hpp"

namespace tensegrity::view {

namespace fs = std::filesystem;
namespace evo = sim::evolve;

struct EvolveWatch::State {
  fs::file_time_type mtime{};
  bool have = false;
  std::string status = "waiting";
  std::string message;
  evo::Checkpoint checkpoint;
  std::optional<sim::Robot> robot;
  std::string robot_json;
  std::int64_t best_episode = -1;
  int best_version = 0;
  int replay_version = 0;
  std::string replay;
};

EvolveWatch::EvolveWatch(const EvolveWatchOptions& options) : options_(options), state_(std::make_unique<State>()) {
  state_->message = "no checkpoint yet in " + options.dir.string() + " (tensegrity evolve --checkpoint DIR)";
  thread_ = std::thread([this] { loop(); });
}

EvolveWatch::~EvolveWatch() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  stop_cv_.notify_all();
  thread_.join();
}

namespace {

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return std::move(s).str();
}

}  // namespace

bool EvolveWatch::poll() {
  const fs::path file = options_.dir / evo::kCheckpointFile;
  std::error_code ec;
  const auto mtime = fs::last_write_time(file, ec);
  if (ec) return false;
  {
    std::lock_guard lock(mutex_);
    if (state_->have && mtime == state_->mtime) return false;
  }
  try {
    evo::Checkpoint c = evo::parse_checkpoint(read_text(file), file.string());
    std::optional<sim::Robot> robot;
    std::string robot_text;
    {
      std::lock_guard lock(mutex_);
      robot = state_->robot;
    }
    if (!robot) {
      const fs::path path = options_.robot.empty() ? sim::robot_path_named(c.config.robot_name) : options_.robot;
      robot = sim::load_robot(path);
      if (robot->hash != c.config.robot_hash) {
        throw std::runtime_error(path.string() + " is not the robot this evolution learns on (hash " + robot->hash +
                                 ", the run's " + c.config.robot_hash + "): give the right one with --robot");
      }
      robot_text = view::robot_json(*robot);
    }
    std::lock_guard lock(mutex_);
    State& s = *state_;
    if (!s.robot) {
      s.robot = std::move(robot);
      s.robot_json = std::move(robot_text);
    }
    s.mtime = mtime;
    s.have = true;
    s.checkpoint = std::move(c);
    const auto& st = s.checkpoint.state;
    s.status = st.episodes >= s.checkpoint.config.episodes ? "finished" : "running";
    s.message.clear();
    if (st.best.found && st.best.episode != s.best_episode) {
      s.best_episode = st.best.episode;
      ++s.best_version;
    }
    return true;
  } catch (const std::exception& e) {
    std::lock_guard lock(mutex_);
    state_->status = "error";
    state_->message = e.what();
    state_->mtime = mtime;
    state_->have = true;
    return false;
  }
}

void EvolveWatch::simulate_best() {
  evo::Checkpoint c;
  sim::Robot robot;
  int version = 0;
  {
    std::lock_guard lock(mutex_);
    if (!state_->robot || state_->replay_version == state_->best_version) return;
    c = state_->checkpoint;
    robot = *state_->robot;
    version = state_->best_version;
  }
  const auto& best = c.state.best;
  const sim::Policy policy = evo::team_policy(robot, c.config.period_s, c.config.complexity, best.team);
  sim::CoreController controller(robot, policy);
  ReplaySink sink;
  sim::EpisodeOptions options;  // as evo::evaluate_team scores it
  options.duration_s = c.config.duration_s;
  options.start = sim::StartKind::settled;
  options.telemetry = &sink;
  sim::run_episode(robot, controller, options);
  char source[160];
  std::snprintf(source, sizeof source, "best team of generation %d (%.2f m in %.0f s), %s", best.generation,
                best.score_m, c.config.duration_s, options_.dir.filename().string().c_str());
  std::string replay = view::replay_json(sink.take(), source);
  std::lock_guard lock(mutex_);
  state_->replay = std::move(replay);
  state_->replay_version = version;
}

void EvolveWatch::loop() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    lock.unlock();
    poll();
    try {
      simulate_best();
    } catch (const std::exception& e) {
      std::lock_guard l(mutex_);
      state_->message = std::string("replaying the best team failed: ") + e.what();
    }
    lock.lock();
    stop_cv_.wait_for(lock, std::chrono::duration<double>(options_.poll_s), [this] { return stopping_; });
  }
}

std::string EvolveWatch::curve_json() const {
  std::lock_guard lock(mutex_);
  const State& s = *state_;
  nlohmann::json j{{"dir", options_.dir.string()},
                   {"state", s.status},
                   {"message", s.message},
                   {"best_version", s.best_version},
                   {"replay_version", s.replay_version}};
  if (s.have && s.status != "error") {
    const auto& st = s.checkpoint.state;
    j["generation"] = st.generation;
    j["episodes"] = st.episodes;
    j["budget"] = s.checkpoint.config.episodes;
    j["method"] = evo::to_string(s.checkpoint.config.method);
    j["best_score_m"] = st.best.score_m;
    j["best_generation"] = st.best.generation;
    nlohmann::json curve{{"generation", nlohmann::json::array()},
                         {"best_score_m", nlohmann::json::array()},
                         {"mean_score_m", nlohmann::json::array()},
                         {"infeasible_rate", nlohmann::json::array()},
                         {"best_so_far_m", nlohmann::json::array()}};
    for (const auto& g : st.curve) {
      curve["generation"].push_back(g.generation);
      curve["best_score_m"].push_back(g.best_score_m);
      curve["mean_score_m"].push_back(g.mean_score_m);
      curve["infeasible_rate"].push_back(g.infeasible_rate());
      curve["best_so_far_m"].push_back(g.best_so_far_m);
    }
    j["curve"] = curve;
  }
  return j.dump();
}

std::optional<std::string> EvolveWatch::replay_json() const {
  std::lock_guard lock(mutex_);
  if (state_->replay.empty()) return std::nullopt;
  return state_->replay;
}

std::optional<std::string> EvolveWatch::robot_json() const {
  std::lock_guard lock(mutex_);
  if (!state_->robot) return std::nullopt;
  return state_->robot_json;
}

}  // namespace tensegrity::view
