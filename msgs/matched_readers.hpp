// SPDX-License-Identifier: Apache-2.0
// The participants whose readers a writer is matched with. A tool that has heard an
// end cap has matched the end cap's writers, not yet the end cap its own: the two
// directions of endpoint discovery finish apart, under load by a second or more
// (Estop.AClearFaultIssuedBeforeAnotherToolsEstopDoesNotUndoIt saw an estop from a
// fresh tool land 1 s late). Until its command reader has matched, every command
// to that end cap is written to nobody. A station counts an end cap ready when it
// is heard *and* its readers are matched (Station::wait_for_endcaps).
#pragma once

#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/rtps/common/Guid.h>

#include <map>
#include <mutex>

namespace tensegrity::msgs {

class MatchedReaders final : public eprosima::fastdds::dds::DataWriterListener {
 public:
  void on_publication_matched(eprosima::fastdds::dds::DataWriter* writer,
                              const eprosima::fastdds::dds::PublicationMatchedStatus& status) override;
  // True while a reader of that participant is matched with the writer.
  bool reaches(const eprosima::fastrtps::rtps::GuidPrefix_t& participant) const;

 private:
  mutable std::mutex mutex_;
  std::map<eprosima::fastrtps::rtps::GuidPrefix_t, int> readers_of_participant_;
};

}  // namespace tensegrity::msgs
