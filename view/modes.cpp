// SPDX-License-Identifier: Apache-2.0
#include "view/modes.hpp"

#include <nlohmann/json.hpp>

#include "view/evolve_watch.hpp"
#include "view/live_bridge.hpp"
#include "view/replay_data.hpp"
#include "view/robot_json.hpp"

namespace tensegrity::view {

namespace {

std::string mode_json(const char* mode, const std::string& title) {
  return nlohmann::json{{"mode", mode}, {"title", title}}.dump();
}

}  // namespace

ReplayView::ReplayView(const std::filesystem::path& csv, const sim::Robot& robot, const ServerOptions& server)
    : server_(server) {
  const ReplayFrames frames = load_replay_csv(csv, robot, warnings_);
  frames_ = frames.frames();
  replay_ = replay_json(frames, csv.filename().string());
  robot_ = robot_json(robot);
  const std::string mode = mode_json("replay", csv.filename().string());
  server_.json("/api/mode", [mode] { return mode; });
  server_.json("/api/robot", [this] { return robot_; });
  server_.json("/api/replay", [this] { return replay_; });
  server_.start();
}

LiveView::LiveView(const sim::Robot& robot, int domain, const ServerOptions& server,
                   const std::filesystem::path& enclave_dir)
    : robot_(robot), robot_json_(robot_json(robot)), server_(server) {
  LiveOptions options;
  options.domain = domain;
  options.enclave_dir = enclave_dir;
  bridge_ = std::make_unique<LiveBridge>(robot_, options, hub_);
  const std::string mode = mode_json("live", "live, DDS domain " + std::to_string(domain));
  server_.json("/api/mode", [mode] { return mode; });
  server_.json("/api/robot", [this] { return robot_json_; });
  server_.json("/api/live/status", [this] { return bridge_->status_json(); });
  // The page's clock against the host's, so that it can tell a sample's age.
  server_.json("/api/clock",
               [] { return "{\"host_ms\":" + std::to_string(static_cast<double>(LiveBridge::now_ns()) / 1e6) + "}"; });
  server_.events("/api/live/events", hub_,
                 [this] { return "event: status\ndata: " + bridge_->status_json() + "\n\n"; });
  server_.start();
}

LiveView::~LiveView() {
  server_.stop();  // no page reads the bridge after this
  bridge_.reset();
}

EvolveView::EvolveView(const std::filesystem::path& dir, const std::filesystem::path& robot,
                       const ServerOptions& server)
    : server_(server) {
  EvolveWatchOptions options;
  options.dir = dir;
  options.robot = robot;
  watch_ = std::make_unique<EvolveWatch>(options);
  const std::string mode = mode_json("evolve", "evolution in " + dir.string());
  server_.json("/api/mode", [mode] { return mode; });
  server_.json("/api/robot", [this] { return watch_->robot_json(); });
  server_.json("/api/evolve/curve", [this] { return watch_->curve_json(); });
  server_.json("/api/replay", [this] { return watch_->replay_json(); });
  server_.start();
}

EvolveView::~EvolveView() {
  server_.stop();
  watch_.reset();
}

}  // namespace tensegrity::view
