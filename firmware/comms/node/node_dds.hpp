// SPDX-License-Identifier: Apache-2.0
// The DDS entities of one EndcapNode (internal to firmware/comms/node).
#pragma once

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>

#include <atomic>
#include <cstdio>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "firmware/comms/node/endcap_node.hpp"
#include "msgs/dds.hpp"

namespace tensegrity::fw::comms {

namespace dds = eprosima::fastdds::dds;

// Calls `fn` from Fast DDS's receive thread when a reader has data.
class CallbackListener final : public dds::DataReaderListener {
 public:
  CallbackListener(std::function<void()> fn, std::string topic, int endcap, bool log)
      : fn_(std::move(fn)), topic_(std::move(topic)), endcap_(endcap), log_(log) {}
  void on_data_available(dds::DataReader*) override { fn_(); }
  void on_requested_incompatible_qos(dds::DataReader*, const dds::RequestedIncompatibleQosStatus& status) override {
    // Loud: a peer with other QoS on one of our topics is a configuration error.
    if (log_) {
      std::fprintf(stderr, "endcap %d: incompatible QoS offered on %s (policy id %u)\n", endcap_, topic_.c_str(),
                   static_cast<unsigned>(status.last_policy_id));
    }
  }

 private:
  std::function<void()> fn_;
  std::string topic_;
  int endcap_;
  bool log_;
};

struct EndcapNode::Dds {
  dds::DomainParticipant* participant = nullptr;
  dds::Publisher* publisher = nullptr;
  dds::Subscriber* subscriber = nullptr;
  dds::DataWriter* policy_ack = nullptr;
  dds::DataWriter* command_ack = nullptr;
  dds::DataWriter* telemetry = nullptr;
  dds::DataWriter* heartbeat = nullptr;
  dds::DataWriter* sync_request = nullptr;
  dds::DataReader* policy = nullptr;
  dds::DataReader* command = nullptr;
  dds::DataReader* host_heartbeat = nullptr;
  dds::DataReader* sync_reply = nullptr;
  std::vector<std::unique_ptr<CallbackListener>> listeners;
  // The command and time-sync listeners run on Fast DDS's receive threads and use
  // this object from the moment their readers exist until the participant is
  // gone: close() lets a callback in progress finish (it holds the mutex), then
  // refuses later ones, and only then deletes anything. Without it, a reply
  // arriving while the node stopped reached through a half-destroyed object
  // (seen: SIGSEGV at exit).
  std::mutex callback_mutex;
  std::atomic<bool> muted{false};  // fault injection: its transport sends nothing (EndcapNodeConfig)
  bool closed = false;             // guarded by callback_mutex
  bool retiring = false;           // replaced by a new participant, still listening; guarded by callback_mutex
  // The other participant during a rejoin's overlap, which a command listener acks on
  // too (node_commands.cpp); guarded by EndcapNode::receive_mutex_, and cleared under it
  // before either participant closes.
  Dds* peer = nullptr;

  ~Dds() { close(); }
  void close() noexcept {
    {
      std::lock_guard lock(callback_mutex);
      closed = true;
    }
    msgs::delete_participant(participant);
    participant = nullptr;
  }
  dds::DataWriter* writer(const msgs::TopicSpec& spec, dds::TypeSupport type) {
    return msgs::create_writer(*participant, *publisher, spec, type);
  }
  dds::DataReader* reader(const msgs::TopicSpec& spec, dds::TypeSupport type, CallbackListener* listener) {
    return msgs::create_reader(*participant, *subscriber, spec, type, listener);
  }
};

}  // namespace tensegrity::fw::comms
