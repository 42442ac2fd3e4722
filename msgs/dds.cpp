// SPDX-License-Identifier: Apache-2.0
#include "msgs/dds.hpp"

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/topic/Topic.hpp>

#include <charconv>
#include <cstdlib>
#include <mutex>

#include "msgs/link_cut_transport.hpp"
#include "msgs/security.hpp"

namespace tensegrity::msgs {

extern const std::string_view kQosProfilesXml;

namespace dds = eprosima::fastdds::dds;

int parse_domain_id(std::string_view text) {
  int value = -1;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc{} || end != text.data() + text.size() || value < 0 || value > 232) {
    throw DdsError("TENSEGRITY_DOMAIN='" + std::string(text) + "': expected an integer domain id 0..232");
  }
  return value;
}

int domain_id() {
  const char* env = std::getenv("TENSEGRITY_DOMAIN");
  if (env == nullptr || *env == '\0') return kDefaultDomain;
  return parse_domain_id(env);
}

void load_qos_profiles() {
  static std::once_flag once;
  static std::string error;
  std::call_once(once, [] {
    auto* factory = dds::DomainParticipantFactory::get_instance();
    const char* file = std::getenv("TENSEGRITY_QOS_FILE");
    ReturnCode_t rc;
    if (file != nullptr && *file != '\0') {
      rc = factory->load_XML_profiles_file(file);
      if (rc != ReturnCode_t::RETCODE_OK) error = std::string("TENSEGRITY_QOS_FILE=") + file + ": Fast DDS rejected it";
    } else {
      rc = factory->load_XML_profiles_string(kQosProfilesXml.data(), kQosProfilesXml.size());
      if (rc != ReturnCode_t::RETCODE_OK) error = "compiled-in msgs/qos_profiles.xml: Fast DDS rejected it";
    }
  });
  if (!error.empty()) throw DdsError(error);
}

dds::DomainParticipant* create_participant(int domain, const std::string& name, const LinkFaults& faults,
                                           const std::filesystem::path& enclave_dir,
                                           dds::DomainParticipantListener* listener) {
  load_qos_profiles();
  auto* factory = dds::DomainParticipantFactory::get_instance();
  dds::DomainParticipantQos qos;
  if (factory->get_participant_qos_from_profile(kParticipantProfile, qos) != ReturnCode_t::RETCODE_OK) {
    throw DdsError(std::string("QoS profile '") + kParticipantProfile + "' not found");
  }
  qos.name(name);
  if (!enclave_dir.empty()) apply_security(qos, enclave_files(enclave_dir));
  if (faults.cut != nullptr || faults.mute != nullptr) {
    for (auto& transport : qos.transport().user_transports) {
      transport = make_link_cut_transport(transport, faults.cut, faults.mute);
    }
  }
  dds::DomainParticipant* participant =
      factory->create_participant(static_cast<dds::DomainId_t>(domain), qos, listener, dds::StatusMask::none());
  if (participant == nullptr) {
    throw DdsError("cannot create DDS participant '" + name + "' on domain " + std::to_string(domain) +
                   (enclave_dir.empty() ? std::string()
                                        : " with enclave " + enclave_dir.string() +
                                              " (Fast DDS refused its certificate, key or signed documents)"));
  }
  return participant;
}

void delete_participant(dds::DomainParticipant* participant) noexcept {
  if (participant == nullptr) return;
  participant->delete_contained_entities();
  dds::DomainParticipantFactory::get_instance()->delete_participant(participant);
}

dds::Topic* create_topic(dds::DomainParticipant& participant, const TopicSpec& spec, dds::TypeSupport type) {
  if (participant.find_type(spec.type).empty()) {
    // No XTypes TypeInformation (PID 0x75) in our endpoints' discovery data: Fast
    // DDS 2.9 encodes it without the XCDR2 headers XTypes 1.3 requires, and a
    // compliant peer (Cyclone DDS 0.10) then drops the whole announcement, so the
    // topic never matches. Fast DDS peers match on the type name and the older
    // TypeObject (still sent); see docs/design/dds.md "A second vendor: Cyclone DDS".
    type->auto_fill_type_information(false);
    if (type.register_type(&participant) != ReturnCode_t::RETCODE_OK) {
      throw DdsError(std::string("cannot register type ") + spec.type);
    }
  }
  if (type.get_type_name() != spec.type) {
    throw DdsError(std::string("topic ") + spec.name + ": type " + type.get_type_name() + ", expected " + spec.type);
  }
  // A second writer or reader of a topic on one participant shares its Topic.
  if (auto* existing = dynamic_cast<dds::Topic*>(participant.lookup_topicdescription(spec.name))) return existing;
  dds::Topic* topic = participant.create_topic(spec.name, spec.type, dds::TOPIC_QOS_DEFAULT);
  if (topic == nullptr) throw DdsError(std::string("cannot create topic ") + spec.name);
  return topic;
}

dds::DataWriter* create_writer(dds::DomainParticipant& participant, dds::Publisher& publisher, const TopicSpec& spec,
                               dds::TypeSupport type, dds::DataWriterListener* listener) {
  dds::Topic* topic = create_topic(participant, spec, type);
  dds::DataWriter* writer = publisher.create_datawriter_with_profile(topic, spec.profile, listener);
  if (writer == nullptr) throw DdsError(std::string("cannot create writer on ") + spec.name);
  return writer;
}

dds::DataReader* create_reader(dds::DomainParticipant& participant, dds::Subscriber& subscriber, const TopicSpec& spec,
                               dds::TypeSupport type, dds::DataReaderListener* listener) {
  dds::Topic* topic = create_topic(participant, spec, type);
  dds::DataReader* reader = subscriber.create_datareader_with_profile(topic, spec.profile, listener);
  if (reader == nullptr) throw DdsError(std::string("cannot create reader on ") + spec.name);
  return reader;
}

}  // namespace tensegrity::msgs
