// SPDX-License-Identifier: Apache-2.0
// DDS Security (OMG DDS-Security 1.1, Fast DDS's built-in PKI-DH, Access-Permissions
// and AES-GCM-GMAC plugins): who may publish and read which topic, the keystore's
// layout (SROS2's: one enclave folder per identity), and the participant properties
// that turn the plugins on. The governance and permissions documents are made from
// kAllTopics' writer column, so a new topic cannot be forgotten. docs/guide/security.md.
#pragma once

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "msgs/dds.hpp"

namespace tensegrity::msgs {

// The identities of the system. The ground station gives orders; an end cap answers
// and reports; a listener (a ROS 2 node, a second monitor) only reads.
enum class Role : std::uint8_t { ground, endcap, listener };

inline constexpr int kMaxEndcaps = 12;

// SROS2 enclave names: "/tensegrity/ground", "/tensegrity/endcap_03", "/tensegrity/listener".
// Throws DdsError for an end cap id outside 0..11.
std::string enclave_name(Role role, int endcap_id = -1);
// KEYSTORE/enclaves/<enclave name without its leading '/'>.
std::filesystem::path enclave_dir(const std::filesystem::path& keystore, const std::string& enclave);
// Who an enclave name is; throws DdsError for a name that is not the project's.
struct Identity {
  Role role;
  int endcap_id;  // -1 unless role is endcap
};
Identity identity_of(const std::string& enclave);
// Every enclave of a full keystore: ground, the 12 end caps, listener.
std::vector<std::string> all_enclaves();

// Where a keystore is looked for when no --keystore is given: TENSEGRITY_KEYSTORE if
// set, else $XDG_DATA_HOME/tensegrity/keystore (~/.local/share/tensegrity/keystore).
std::filesystem::path default_keystore();

// The files of one enclave, as SROS2 names them.
struct EnclaveFiles {
  std::filesystem::path identity_ca;     // identity_ca.cert.pem
  std::filesystem::path certificate;     // cert.pem
  std::filesystem::path private_key;     // key.pem
  std::filesystem::path permissions_ca;  // permissions_ca.cert.pem
  std::filesystem::path governance;      // governance.p7s
  std::filesystem::path permissions;     // permissions.p7s
  // crl.pem, the CA's certificate revocation list (`tensegrity security revoke`):
  // optional, empty when the enclave has none. With it, a participant refuses peers
  // whose certificate the list revokes.
  std::filesystem::path revocations;
};
EnclaveFiles enclave_files(const std::filesystem::path& enclave_dir);
// Throws DdsError naming the first file that is missing or unreadable.
void check_enclave(const EnclaveFiles& files);

// Turns the three built-in plugins on in `qos` with `files` (checked first).
void apply_security(eprosima::fastdds::dds::DomainParticipantQos& qos, const EnclaveFiles& files);

// Which topics `role` may write and read (from kAllTopics' writer column).
bool may_publish(Role role, const TopicSpec& topic);
bool may_subscribe(Role role, const TopicSpec& topic);

// The unsigned documents (the keystore signs them with its CA). Validity in UTC,
// "YYYY-MM-DDTHH:MM:SS". The subject is the certificate's, "CN=<enclave name>".
std::string governance_xml();
std::string permissions_xml(const std::string& enclave, const std::string& not_before, const std::string& not_after);
// The grant's <allow_rule> for `enclave` as this version writes it: a keystore whose
// permissions.xml lacks it was made by another version (ground/keystore.hpp).
std::string permission_rules(const std::string& enclave);
std::string subject_name(const std::string& enclave);

}  // namespace tensegrity::msgs
