// SPDX-License-Identifier: Apache-2.0
#include "msgs/matched_readers.hpp"

#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/rtps/common/InstanceHandle.h>

namespace tensegrity::msgs {

namespace dds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

void MatchedReaders::on_publication_matched(dds::DataWriter*, const dds::PublicationMatchedStatus& status) {
  rtps::GUID_t reader;
  rtps::iHandle2GUID(reader, status.last_subscription_handle);
  std::lock_guard lock(mutex_);
  int& readers = readers_of_participant_[reader.guidPrefix];
  readers += status.current_count_change > 0 ? 1 : (status.current_count_change < 0 ? -1 : 0);
  if (readers <= 0) readers_of_participant_.erase(reader.guidPrefix);
}

bool MatchedReaders::reaches(const rtps::GuidPrefix_t& participant) const {
  std::lock_guard lock(mutex_);
  return readers_of_participant_.count(participant) != 0;
}

}  // namespace tensegrity::msgs
