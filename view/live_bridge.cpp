// SPDX-License-Identifier: Apache-2.0
#include "view/live_bridge.hpp"

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <vector>

#include <nlohmann/json.hpp>

#include "firmware/hal/monotonic.hpp"
#include "ground/status.hpp"
#include "msgs/dds.hpp"
#include "msgs/endcap_writers.hpp"
#include "tensegrity_msgs/msg/HeartbeatPubSubTypes.h"
#include "tensegrity_msgs/msg/TelemetryPubSubTypes.h"

namespace tensegrity::view {

namespace dds = eprosima::fastdds::dds;
namespace msg = tensegrity_msgs::msg::dds_;

struct LiveReaders {
  class Listener final : public dds::DataReaderListener {
   public:
    Listener(LiveBridge& bridge, const msgs::EndcapWriters& writers, bool telemetry)
        : bridge_(bridge), writers_(writers), telemetry_(telemetry) {}
    void on_data_available(dds::DataReader* reader) override {
      if (telemetry_) {
        take<msg::Telemetry_>(reader, &LiveBridge::on_telemetry_sample);
      } else {
        take<msg::Heartbeat_>(reader, &LiveBridge::on_heartbeat_sample);
      }
    }

   private:
    template <typename T>
    void take(dds::DataReader* reader, void (LiveBridge::*fn)(const void*, std::int64_t)) {
      T sample;
      dds::SampleInfo info;
      while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
        const std::int64_t now = LiveBridge::now_ns();
        if (!info.valid_data || sample.format_version() != msgs::kFormatVersion) continue;
        // Only what its writer may say: end cap N's reports from end cap N's partition.
        if (!writers_.vouches(info, endcap_of(sample))) continue;
        (bridge_.*fn)(&sample, now);
      }
    }
    static int endcap_of(const msg::Telemetry_& t) { return t.endcap_id(); }
    static int endcap_of(const msg::Heartbeat_& h) { return h.source(); }
    LiveBridge& bridge_;
    const msgs::EndcapWriters& writers_;
    bool telemetry_;
  };
};

struct LiveBridge::Dds {
  msgs::EndcapWriters writers;  // outlives the participant, which calls it
  dds::DomainParticipant* participant = nullptr;
  std::vector<std::unique_ptr<LiveReaders::Listener>> listeners;
  ~Dds() { msgs::delete_participant(participant); }
};

std::int64_t LiveBridge::now_ns() { return fw::monotonic_ns(); }

LiveBridge::LiveBridge(const sim::Robot& robot, const LiveOptions& options, EventHub& hub)
    : robot_(robot), options_(options), hub_(hub), dds_(std::make_unique<Dds>()) {
  // Through msgs::create_participant, like every participant of the project: the
  // same transport, QoS profiles and (where configured) security.
  dds_->participant = msgs::create_participant(options.domain, "view", {}, options.enclave_dir, &dds_->writers);
  dds::Subscriber* subscriber = dds_->participant->create_subscriber(msgs::endcap_reports_qos());
  if (subscriber == nullptr) throw msgs::DdsError("view: cannot create a subscriber");
  for (bool telemetry : {true, false}) {
    dds_->listeners.push_back(std::make_unique<LiveReaders::Listener>(*this, dds_->writers, telemetry));
    msgs::create_reader(*dds_->participant, *subscriber,
                        telemetry ? msgs::kTelemetryTopic : msgs::kEndcapHeartbeatTopic,
                        telemetry ? dds::TypeSupport(new msg::Telemetry_PubSubType())
                                  : dds::TypeSupport(new msg::Heartbeat_PubSubType()),
                        dds_->listeners.back().get());
  }
  status_thread_ = std::thread([this] { status_loop(); });
}

LiveBridge::~LiveBridge() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  stop_cv_.notify_all();
  status_thread_.join();
  dds_.reset();  // no callback runs after this
}

dds::DomainParticipant& LiveBridge::participant() { return *dds_->participant; }

void LiveBridge::on_telemetry_sample(const void* sample, std::int64_t received_ns) {
  const auto& t = *static_cast<const msg::Telemetry_*>(sample);
  const int e = t.endcap_id();
  if (e < 0 || e >= kLiveEndcaps || e >= robot_.endcap_count()) return;
  {
    std::lock_guard lock(mutex_);
    Endcap& s = endcaps_[static_cast<std::size_t>(e)];
    if (s.telemetry > 0 && t.seq() > s.last_seq + 1) s.gaps += t.seq() - s.last_seq - 1;
    s.last_seq = t.seq();
    ++s.telemetry;
  }
  const std::vector<int> cables = robot_.cables_of(e);
  const std::size_t n = std::min<std::size_t>({cables.size(), t.motor_count(), 4});
  char buf[256];
  // Host times in ms with three decimals: a JS number holds them exactly.
  std::snprintf(buf, sizeof buf,
                "{\"e\":%d,\"seq\":%u,\"sample_host_ms\":%.3f,\"received_host_ms\":%.3f,\"mode\":%u,\"fault\":%u", e,
                t.seq(), t.host_time_ns() == 0 ? -1.0 : static_cast<double>(t.host_time_ns()) / 1e6,
                static_cast<double>(received_ns) / 1e6, unsigned{t.mode()}, unsigned{t.fault()});
  std::string json = buf;
  const auto list = [&](const char* name, auto&& value) {
    json += ",\"";
    json += name;
    json += "\":[";
    for (std::size_t k = 0; k < n; ++k) {
      std::snprintf(buf, sizeof buf, k == 0 ? "%.4g" : ",%.4g", static_cast<double>(value(k)));
      json += buf;
    }
    json += ']';
  };
  list("cables", [&](std::size_t k) { return cables[k]; });
  list("tension_n", [&](std::size_t k) { return t.tension_n()[k]; });
  list("commanded_m", [&](std::size_t k) { return t.commanded_rest_length_m()[k]; });
  list("measured_m", [&](std::size_t k) { return t.measured_rest_length_m()[k]; });
  json += '}';
  std::lock_guard lock(mutex_);
  std::string& slot = pending_[static_cast<std::size_t>(e)];
  if (!slot.empty()) ++superseded_;
  slot = std::move(json);
}

void LiveBridge::publish_frame() {
  std::string frame;
  {
    std::lock_guard lock(mutex_);
    for (std::string& s : pending_) {
      if (s.empty()) continue;
      frame += frame.empty() ? "[" : ",";
      frame += s;
      s.clear();
    }
  }
  if (frame.empty()) return;
  frame += ']';
  hub_.publish("telemetry", frame);
}

void LiveBridge::on_heartbeat_sample(const void* sample, std::int64_t received_ns) {
  const auto& hb = *static_cast<const msg::Heartbeat_*>(sample);
  const int e = hb.source();
  if (e < 0 || e >= kLiveEndcaps) return;
  std::lock_guard lock(mutex_);
  Endcap& s = endcaps_[static_cast<std::size_t>(e)];
  s.seen = true;
  s.heartbeat_host_ns = received_ns;
  s.mode = hb.mode();
  s.fault = hb.fault();
  s.policy = hb.active_policy_id().to_string();
  if (!s.policy.empty()) s.policy += " v" + std::to_string(hb.active_policy_version());
  s.clock_synced = hb.clock_synced();
  s.host_lost = hb.host_lost();
}

std::string LiveBridge::status_json() const {
  const std::int64_t now = now_ns();
  nlohmann::json endcaps = nlohmann::json::array();
  std::lock_guard lock(mutex_);
  for (int e = 0; e < std::min(kLiveEndcaps, robot_.endcap_count()); ++e) {
    const Endcap& s = endcaps_[static_cast<std::size_t>(e)];
    nlohmann::json j{{"e", e}, {"seen", s.seen}, {"telemetry", s.telemetry}, {"gaps", s.gaps}};
    if (s.seen) {
      j["heartbeat_age_s"] = static_cast<double>(now - s.heartbeat_host_ns) / 1e9;
      j["state"] = ground::mode_name(static_cast<std::uint8_t>(s.mode));
      j["fault"] = ground::fault_name(static_cast<std::uint8_t>(s.fault));
      j["policy"] = s.policy;
      j["clock_synced"] = s.clock_synced;
      j["host_lost"] = s.host_lost;
    }
    endcaps.push_back(j);
  }
  return nlohmann::json{{"domain", options_.domain},
                        {"now_host_ms", static_cast<double>(now) / 1e6},
                        {"frame_rate_hz", options_.frame_rate_hz},
                        {"superseded", superseded_},
                        {"endcaps", endcaps}}
      .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);  // policy ids: the end caps' bytes
}

void LiveBridge::status_loop() {
  using clock = std::chrono::steady_clock;
  const auto frame_period =
      std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(1.0 / options_.frame_rate_hz));
  const auto status_period =
      std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(1.0 / options_.status_rate_hz));
  auto next_frame = clock::now();
  auto next_status = next_frame;
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    lock.unlock();
    const auto now = clock::now();
    if (now >= next_status) {
      hub_.publish("status", status_json());
      next_status = now + status_period;
    }
    publish_frame();
    next_frame = std::max(next_frame + frame_period, now);  // no burst after a stall
    lock.lock();
    stop_cv_.wait_until(lock, std::min(next_frame, next_status), [this] { return stopping_; });
  }
}

}  // namespace tensegrity::view
