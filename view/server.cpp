// SPDX-License-Identifier: Apache-2.0
#include "view/server.hpp"

#include <httplib.h>

#include "view/assets.hpp"
#include "view/csv_table.hpp"

namespace tensegrity::view {

namespace {

// Each open event stream holds one thread: enough for several pages and the
// requests of each.
constexpr std::size_t kHttpThreads = 24;
constexpr const char* kThreeModule = "build/three.module.js";
// With a parameter these types are not ones cpp-httplib compresses: on loopback
// compression only costs time (its Brotli runs at the slowest quality), and
// three.js is a megabyte.
constexpr const char* kJson = "application/json; charset=utf-8";
constexpr const char* kJavaScript = "application/javascript; charset=utf-8";

void serve_asset(const httplib::Request& req, httplib::Response& res) {
  const Asset* a = find_asset(req.path == "/" ? "/index.html" : req.path);
  if (a == nullptr) {
    res.status = 404;
    res.set_content("not found\n", "text/plain");
    return;
  }
  res.set_header("Cache-Control", "no-cache");
  res.set_content(std::string(a->body), std::string(a->content_type));
}

void refuse(const httplib::Request&, httplib::Response& res) {
  res.status = 405;
  res.set_header("Allow", "GET, HEAD");
  res.set_content("the view is read-only\n", "text/plain");
}

}  // namespace

ViewServer::ViewServer(const ServerOptions& options) : options_(options), http_(std::make_unique<httplib::Server>()) {
  if (!std::filesystem::exists(options_.three_dir / kThreeModule)) {
    throw InputError((options_.three_dir / kThreeModule).string() +
                     " not found: install Debian's libjs-three (scripts/setup.sh does), or give --three-dir");
  }
  http_->new_task_queue = [] { return new httplib::ThreadPool(kHttpThreads); };
  http_->set_file_extension_and_mimetype_mapping("js", kJavaScript);
  http_->set_mount_point("/three", options_.three_dir.string());
  http_->Get(R"(/|/index\.html|/js/[A-Za-z0-9_\-]+\.js|/[A-Za-z0-9_\-]+\.css)", serve_asset);
  for (const char* any : {".*"}) {
    http_->Post(any, refuse);
    http_->Put(any, refuse);
    http_->Delete(any, refuse);
    http_->Patch(any, refuse);
    http_->Options(any, refuse);
  }
}

ViewServer::~ViewServer() { stop(); }

void ViewServer::json(const std::string& path, std::function<std::optional<std::string>()> body) {
  http_->Get(path, [body = std::move(body)](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    const std::optional<std::string> text = body();
    if (!text) {
      res.status = 503;
      res.set_content("{\"pending\":true}", kJson);
      return;
    }
    res.set_content(*text, kJson);
  });
}

void ViewServer::events(const std::string& path, EventHub& hub, std::function<std::string()> hello) {
  hubs_.push_back(&hub);
  http_->Get(path, [&hub, hello = std::move(hello)](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    struct Stream {
      std::uint64_t cursor = 0;
      std::uint64_t skipped = 0;
      bool greeted = false;
    };
    auto stream = std::make_shared<Stream>();
    stream->cursor = hub.head();
    res.set_chunked_content_provider(
        "text/event-stream",
        [&hub, hello, stream](std::size_t, httplib::DataSink& sink) {
          if (!stream->greeted) {
            stream->greeted = true;
            hub.reader_joined();
            // retry: how soon the browser reconnects after the server went away.
            const std::string first = "retry: 1000\n\n" + hello();
            return sink.write(first.data(), first.size());
          }
          // A comment line when idle: a closed page is noticed within a second.
          std::string chunk = hub.take(&stream->cursor, 1000, &stream->skipped);
          if (hub.closed()) return false;
          if (chunk.empty()) chunk = ": idle\n\n";
          return sink.write(chunk.data(), chunk.size());
        },
        [&hub, stream](bool) {
          if (stream->greeted) hub.reader_left();
        });
  });
}

void ViewServer::start() {
  port_ = options_.port == 0 ? http_->bind_to_any_port(options_.bind) : options_.port;
  if (options_.port != 0 && !http_->bind_to_port(options_.bind, options_.port)) port_ = -1;
  if (port_ < 0) {
    throw InputError("cannot listen on " + options_.bind + ":" + std::to_string(options_.port) +
                     " (in use, or not an address of this machine): choose another with --port/--bind");
  }
  thread_ = std::thread([this] { http_->listen_after_bind(); });
}

void ViewServer::stop() {
  if (!thread_.joinable()) return;
  for (EventHub* hub : hubs_) hub->close();
  http_->stop();
  thread_.join();
}

std::string ViewServer::url() const {
  const std::string host = options_.bind.find(':') != std::string::npos ? "[" + options_.bind + "]" : options_.bind;
  return "http://" + host + ":" + std::to_string(port_) + "/";
}

}  // namespace tensegrity::view
