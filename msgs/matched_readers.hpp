// SPDX-License-Identifier: Apache-2.0
// The participants whose readers a writer is matched with. A tool that hears an end
// cap has matched its readers to the end cap's writers; the end cap may not yet have
// matched its readers to the tool's writers: the two directions of endpoint discovery
// finish apart, under load by up to a second (an estop from a fresh tool landed 0.5 s
// after it was sent in CI and 1.0 s in a loaded reproduction of
// Estop.AClearFaultIssuedBeforeAnotherToolsEstopDoesNotUndoIt). Until the end cap's
// command reader has matched, every command to it is written to nobody. A station
// counts an end cap ready when it is heard *and* reached (Station::wait_for_endcaps).
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
