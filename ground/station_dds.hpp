// SPDX-License-Identifier: Apache-2.0
// The station's DDS entities and the listeners that take the end caps' samples in
// the receive thread: shared by station.cpp (the station's API) and
// station_listeners.cpp (decoding and vouching for what arrives). Not a public header.
#pragma once

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>

#include <cstdio>
#include <memory>
#include <mutex>
#include <vector>

#include "ground/station.hpp"
#include "msgs/dds.hpp"
#include "msgs/endcap_writers.hpp"
#include "msgs/matched_readers.hpp"

namespace tensegrity::ground {

namespace dds = eprosima::fastdds::dds;

// One listener per reader; each takes its samples in the receive thread.
struct StationListeners {
  class Listener final : public dds::DataReaderListener {
   public:
    Listener(Station& station, void (*fn)(Station&, dds::DataReader*), const char* topic)
        : station_(station), fn_(fn), topic_(topic) {}
    void on_data_available(dds::DataReader* reader) override { fn_(station_, reader); }
    void on_requested_incompatible_qos(dds::DataReader*, const dds::RequestedIncompatibleQosStatus&) override {
      std::fprintf(stderr, "ground: incompatible QoS offered on %s\n", topic_);
    }

   private:
    Station& station_;
    void (*fn_)(Station&, dds::DataReader*);
    const char* topic_;
  };

  // True when the writer of `info` publishes for `endcap` (its partition, which the
  // permissions bind to its identity); else the sample is counted, said now and
  // then, and must be dropped: an end cap speaking for another.
  static bool vouched(Station& s, const dds::SampleInfo& info, int endcap, const char* what);
  static void policy_acks(Station& s, dds::DataReader* r);
  static void command_acks(Station& s, dds::DataReader* r);
  static void telemetry(Station& s, dds::DataReader* r);
  static void heartbeats(Station& s, dds::DataReader* r);
  static void time_sync(Station& s, dds::DataReader* r);
};

struct Station::Dds {
  // Declared first, destroyed last: the participant (deleted in close()) calls it.
  msgs::EndcapWriters writers;
  msgs::MatchedReaders policy_readers, command_readers;  // the writers' listeners
  dds::DomainParticipant* participant = nullptr;
  dds::Publisher* publisher = nullptr;
  dds::Subscriber* subscriber = nullptr;
  dds::DataWriter* policy = nullptr;
  dds::DataWriter* command = nullptr;
  dds::DataWriter* heartbeat = nullptr;
  dds::DataWriter* sync_reply = nullptr;
  std::vector<std::unique_ptr<StationListeners::Listener>> listeners;
  std::mutex write_mutex;  // the time-sync reply writer is used from the receive thread
  // Set (under write_mutex) before anything is deleted: a time-sync request being
  // answered meanwhile finishes first, a later one is not answered. Without it a
  // request arriving while a ground tool exited reached through a half-destroyed
  // object (seen: `tensegrity upload` ending with SIGSEGV after a good upload).
  bool closed = false;

  ~Dds() { close(); }
  void close() noexcept {
    {
      std::lock_guard lock(write_mutex);
      closed = true;
    }
    msgs::delete_participant(participant);
    participant = nullptr;
  }
  dds::DataWriter* writer(const msgs::TopicSpec& spec, dds::TypeSupport type,
                          dds::DataWriterListener* listener = nullptr) {
    return msgs::create_writer(*participant, *publisher, spec, type, listener);
  }
  void reader(Station& station, const msgs::TopicSpec& spec, dds::TypeSupport type,
              void (*fn)(Station&, dds::DataReader*)) {
    listeners.push_back(std::make_unique<StationListeners::Listener>(station, fn, spec.name));
    msgs::create_reader(*participant, *subscriber, spec, type, listeners.back().get());
  }
};

}  // namespace tensegrity::ground
