// SPDX-License-Identifier: Apache-2.0
#include "tests/interop/cyclone/cyclone_link.hpp"

#include <memory>

namespace tensegrity::interop {
namespace {

using QosPtr = std::unique_ptr<dds_qos_t, decltype(&dds_delete_qos)>;

std::string failed(const std::string& what, dds_return_t rc) { return what + ": " + dds_strretcode(rc); }

// msgs/qos_profiles.xml, profile by profile. Two settings have no Fast DDS
// counterpart in that file but are what Fast DDS does anyway:
//  - data representation XCDR1: Fast DDS 2.9 writes and expects plain CDR
//    (XCDR1) for these final types; Cyclone 0.10 would accept either when
//    reading, but says so explicitly here so that neither side ever offers XCDR2
//    (which aligns 8-byte fields to 4 and would garble every double).
//  - durability_service history: Cyclone keeps a transient-local writer's
//    samples for late-joining readers according to it (default KEEP_LAST 1),
//    Fast DDS according to the history QoS. 32 = the history depth, so a
//    late end cap still finds its table among the 12 on this unkeyed topic.
QosPtr make_qos(Profile profile, bool writer) {
  QosPtr q(dds_create_qos(), &dds_delete_qos);
  const dds_data_representation_id_t xcdr1[] = {DDS_DATA_REPRESENTATION_XCDR1};
  dds_qset_data_representation(q.get(), 1, xcdr1);
  switch (profile) {
    case Profile::durable_events:
      dds_qset_reliability(q.get(), DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
      dds_qset_durability(q.get(), DDS_DURABILITY_TRANSIENT_LOCAL);
      dds_qset_history(q.get(), DDS_HISTORY_KEEP_LAST, 32);
      if (writer) dds_qset_durability_service(q.get(), 0, DDS_HISTORY_KEEP_LAST, 32, -1, -1, -1);
      break;
    case Profile::stream:
      dds_qset_reliability(q.get(), DDS_RELIABILITY_BEST_EFFORT, 0);
      dds_qset_durability(q.get(), DDS_DURABILITY_VOLATILE);
      dds_qset_history(q.get(), DDS_HISTORY_KEEP_LAST, writer ? 1 : 64);
      break;
  }
  return q;
}

}  // namespace

CycloneParticipant::CycloneParticipant(int domain) {
  if (domain < 0 || domain > 232) throw CycloneError("domain " + std::to_string(domain) + ": expected 0..232");
  participant_ = dds_create_participant(static_cast<dds_domainid_t>(domain), nullptr, nullptr);
  if (participant_ < 0) {
    throw CycloneError(
        failed("cannot create a Cyclone participant on domain " + std::to_string(domain) + " (check CYCLONEDDS_URI)",
               participant_));
  }
}

CycloneParticipant::~CycloneParticipant() {
  if (participant_ > 0) dds_delete(participant_);
}

dds_entity_t CycloneParticipant::topic(const CycloneTopic& t) {
  // Same name twice returns the same topic in Cyclone: no bookkeeping needed.
  const dds_entity_t topic = dds_create_topic(participant_, t.descriptor, t.name, nullptr, nullptr);
  if (topic < 0) throw CycloneError(failed(std::string("cannot create topic ") + t.name, topic));
  return topic;
}

dds_entity_t CycloneParticipant::writer(const CycloneTopic& t) {
  const QosPtr qos = make_qos(t.profile, true);
  const dds_entity_t w = dds_create_writer(participant_, topic(t), qos.get(), nullptr);
  if (w < 0) throw CycloneError(failed(std::string("cannot create writer on ") + t.name, w));
  return w;
}

dds_entity_t CycloneParticipant::reader(const CycloneTopic& t) {
  const QosPtr qos = make_qos(t.profile, false);
  // The peer plays the ground: what it reads, the end caps write, each in its own
  // partition (msgs/endcap_writers.hpp). Cyclone gives the reader's implicit
  // subscriber this QoS, and matches the pattern as Fast DDS does.
  dds_qset_partition1(qos.get(), kEndcapReportsPartition);
  const dds_entity_t r = dds_create_reader(participant_, topic(t), qos.get(), nullptr);
  if (r < 0) throw CycloneError(failed(std::string("cannot create reader on ") + t.name, r));
  return r;
}

std::uint32_t matched_readers(dds_entity_t writer) {
  dds_publication_matched_status_t status{};
  if (dds_get_publication_matched_status(writer, &status) != DDS_RETCODE_OK) return 0;
  return status.current_count;
}

}  // namespace tensegrity::interop
