// SPDX-License-Identifier: Apache-2.0
// Decodes fuzz bytes as a DDS sample exactly as a DataReader would: the bytes are
// a serialized payload (CDR encapsulation header, then the fields) handed to the
// type's generated PubSubType::deserialize. False when the type refuses them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>

#include <fastdds/rtps/common/SerializedPayload.h>

namespace tensegrity::fuzz {

template <typename PubSubType, typename Sample>
bool deserialize_sample(const std::uint8_t* data, std::size_t size, Sample& out) {
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(size));
  if (size > 0) std::memcpy(payload.data, data, size);
  payload.length = static_cast<std::uint32_t>(size);
  PubSubType type;
  try {
    return type.deserialize(&payload, &out);
  } catch (const std::exception&) {
    return false;  // fastcdr reports a short or inconsistent buffer by throwing
  }
}

}  // namespace tensegrity::fuzz
