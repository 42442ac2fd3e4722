// SPDX-License-Identifier: Apache-2.0
// A forged time source for the DDS tests (estop_dds_test, security_dds_test).
#pragma once

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>

#include <cstdint>
#include <filesystem>
#include <mutex>

#include "ground/station.hpp"
#include "msgs/dds.hpp"
#include "msgs/endcap_writers.hpp"
#include "tensegrity_msgs/msg/TimeSyncPubSubTypes.h"

namespace tensegrity::test {

namespace dds = eprosima::fastdds::dds;

// A participant that answers every time-sync request an hour ahead, with t3 - t2
// chosen so that the round trip computes to about 0, and the nonce echoed: the
// attack (without DDS Security anyone on the domain can do this).
class RogueTimeServer final : public dds::DataReaderListener {
 public:
  // `enclave_dir`: a DDS Security identity to try the attack with (empty: none).
  explicit RogueTimeServer(int domain, const std::filesystem::path& enclave_dir = {}) {
    participant_ = msgs::create_participant(domain, "rogue_time_server", {}, enclave_dir);
    auto* pub = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
    // Where the end caps' requests are: every end cap's partition.
    auto* sub = participant_->create_subscriber(msgs::endcap_reports_qos());
    namespace m = tensegrity_msgs::msg::dds_;
    writer_ = msgs::create_writer(*participant_, *pub, msgs::kTimeSyncReplyTopic,
                                  dds::TypeSupport(new m::TimeSyncReply_PubSubType()));
    msgs::create_reader(*participant_, *sub, msgs::kTimeSyncRequestTopic,
                        dds::TypeSupport(new m::TimeSyncRequest_PubSubType()), this);
  }
  ~RogueTimeServer() override {
    {
      std::lock_guard lock(mutex_);
      closed_ = true;
    }
    msgs::delete_participant(participant_);
  }
  void on_data_available(dds::DataReader* reader) override {
    namespace m = tensegrity_msgs::msg::dds_;
    m::TimeSyncRequest_ req;
    dds::SampleInfo info;
    while (reader->take_next_sample(&req, &info) == ReturnCode_t::RETCODE_OK) {
      std::lock_guard lock(mutex_);
      if (closed_ || !info.valid_data) continue;
      const std::int64_t now = ground::Station::now_ns();
      m::TimeSyncReply_ reply;
      reply.format_version(msgs::kFormatVersion);
      reply.endcap_id(req.endcap_id());
      reply.seq(req.seq());
      reply.nonce(req.nonce());
      reply.t1_ns(req.t1_ns());
      reply.t2_ns(now + 3'600'000'000'000);
      reply.t3_ns(reply.t2_ns() + (now - req.t1_ns()) + 50'000);  // round trip ~0
      writer_->write(&reply);
      ++answered_;
    }
  }
  std::uint64_t answered() {
    std::lock_guard lock(mutex_);
    return answered_;
  }

 private:
  dds::DomainParticipant* participant_ = nullptr;
  dds::DataWriter* writer_ = nullptr;
  std::mutex mutex_;
  bool closed_ = false;
  std::uint64_t answered_ = 0;
};

}  // namespace tensegrity::test
