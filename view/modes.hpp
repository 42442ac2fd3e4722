// SPDX-License-Identifier: Apache-2.0
#pragma once
// The three things `tensegrity view` shows, each a server with its data source:
// a recorded run (replay), the end caps over DDS (live) and an evolution (evolve).
// Each serves from construction to destruction; `url()` is where to point a browser.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "robot/robot.hpp"
#include "view/event_hub.hpp"
#include "view/server.hpp"

namespace tensegrity::view {

class LiveBridge;
class EvolveWatch;

class ReplayView {
 public:
  // Reads the whole CSV first (InputError naming line and column), then serves.
  ReplayView(const std::filesystem::path& csv, const sim::Robot& robot, const ServerOptions& server);
  std::string url() const { return server_.url(); }
  const std::vector<std::string>& warnings() const { return warnings_; }
  std::size_t frames() const { return frames_; }

 private:
  std::vector<std::string> warnings_;
  std::size_t frames_ = 0;
  std::string replay_;
  std::string robot_;
  ViewServer server_;
};

class LiveView {
 public:
  // `enclave_dir`: DDS Security enclave (a keystore's listener); empty: unsecured.
  LiveView(const sim::Robot& robot, int domain, const ServerOptions& server,
           const std::filesystem::path& enclave_dir = {});
  ~LiveView();
  std::string url() const { return server_.url(); }
  // True once a page is watching; false after `timeout_s`.
  bool wait_for_page(double timeout_s) const { return hub_.wait_for_reader(static_cast<int>(timeout_s * 1000)); }

 private:
  sim::Robot robot_;
  std::string robot_json_;
  EventHub hub_;
  std::unique_ptr<LiveBridge> bridge_;
  ViewServer server_;
};

class EvolveView {
 public:
  EvolveView(const std::filesystem::path& dir, const std::filesystem::path& robot, const ServerOptions& server);
  ~EvolveView();
  std::string url() const { return server_.url(); }

 private:
  std::unique_ptr<EvolveWatch> watch_;
  ViewServer server_;
};

}  // namespace tensegrity::view
