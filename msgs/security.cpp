// SPDX-License-Identifier: Apache-2.0
#include "msgs/security.hpp"

#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "msgs/endcap_writers.hpp"

namespace tensegrity::msgs {

namespace fs = std::filesystem;

std::string enclave_name(Role role, int endcap_id) {
  switch (role) {
    case Role::ground: return "/tensegrity/ground";
    case Role::listener: return "/tensegrity/listener";
    case Role::endcap: break;
  }
  if (endcap_id < 0 || endcap_id >= kMaxEndcaps) {
    throw DdsError("end cap id " + std::to_string(endcap_id) + ": expected 0.." + std::to_string(kMaxEndcaps - 1));
  }
  char name[32];
  std::snprintf(name, sizeof name, "/tensegrity/endcap_%02d", endcap_id);
  return name;
}

fs::path enclave_dir(const fs::path& keystore, const std::string& enclave) {
  return keystore / "enclaves" / fs::path(enclave).relative_path();
}

std::vector<std::string> all_enclaves() {
  std::vector<std::string> names{enclave_name(Role::ground)};
  for (int id = 0; id < kMaxEndcaps; ++id) names.push_back(enclave_name(Role::endcap, id));
  names.push_back(enclave_name(Role::listener));
  return names;
}

fs::path default_keystore() {
  if (const char* env = std::getenv("TENSEGRITY_KEYSTORE"); env != nullptr && *env != '\0') return env;
  if (const char* xdg = std::getenv("XDG_DATA_HOME"); xdg != nullptr && *xdg != '\0') {
    return fs::path(xdg) / "tensegrity" / "keystore";
  }
  const char* home = std::getenv("HOME");
  return fs::path(home != nullptr && *home != '\0' ? home : ".") / ".local" / "share" / "tensegrity" / "keystore";
}

EnclaveFiles enclave_files(const fs::path& dir) {
  EnclaveFiles files{dir / "identity_ca.cert.pem",
                     dir / "cert.pem",
                     dir / "key.pem",
                     dir / "permissions_ca.cert.pem",
                     dir / "governance.p7s",
                     dir / "permissions.p7s",
                     {}};
  if (fs::exists(dir / "crl.pem")) files.revocations = dir / "crl.pem";
  return files;
}

void check_enclave(const EnclaveFiles& files) {
  for (const fs::path* p : {&files.identity_ca, &files.certificate, &files.private_key, &files.permissions_ca,
                            &files.governance, &files.permissions, &files.revocations}) {
    if (p == &files.revocations && p->empty()) continue;  // optional
    std::ifstream in(*p);
    if (!in) {
      throw DdsError("DDS security: " + p->string() +
                     ": missing or unreadable (create a keystore with `tensegrity security init DIR`)");
    }
  }
}

void apply_security(eprosima::fastdds::dds::DomainParticipantQos& qos, const EnclaveFiles& files) {
  check_enclave(files);
  // Fast DDS reads these lazily, relative to the working directory: give it
  // absolute paths so a process that changes directory still finds them.
  auto file = [](const fs::path& p) { return "file://" + fs::absolute(p).lexically_normal().string(); };
  auto& props = qos.properties().properties();
  props.emplace_back("dds.sec.auth.plugin", "builtin.PKI-DH");
  props.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_ca", file(files.identity_ca));
  props.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_certificate", file(files.certificate));
  props.emplace_back("dds.sec.auth.builtin.PKI-DH.private_key", file(files.private_key));
  if (!files.revocations.empty()) {
    props.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_crl", file(files.revocations));
  }
  props.emplace_back("dds.sec.access.plugin", "builtin.Access-Permissions");
  props.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions_ca", file(files.permissions_ca));
  props.emplace_back("dds.sec.access.builtin.Access-Permissions.governance", file(files.governance));
  props.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions", file(files.permissions));
  props.emplace_back("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
}

bool may_publish(Role role, const TopicSpec& topic) {
  switch (role) {
    case Role::ground: return topic.writer == Writer::ground;
    case Role::endcap: return topic.writer == Writer::endcap;
    case Role::listener: return false;
  }
  return false;
}

bool may_subscribe(Role role, const TopicSpec& topic) {
  // An end cap reads only the ground's orders, never another end cap's reports.
  return role != Role::endcap || topic.writer == Writer::ground;
}

std::string subject_name(const std::string& enclave) { return "CN=" + enclave; }

namespace {

// The whole domain range a project participant may use (TENSEGRITY_DOMAIN, HIL leases).
constexpr const char* kDomains = "<domains><id_range><min>0</min><max>232</max></id_range></domains>";

std::string topic_list(const std::vector<std::string>& names) {
  std::string out = "<topics>";
  for (const auto& n : names) out += "<topic>" + n + "</topic>";
  return out + "</topics>";
}

}  // namespace

std::string governance_xml() {
  // SROS2's default governance: nobody joins unauthenticated, discovery and
  // liveliness encrypted, every RTPS message signed, every topic access-controlled
  // and its data encrypted.
  return std::string(R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-Security/20170801/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      )") +
         kDomains + R"(
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>SIGN</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
)";
}

Identity identity_of(const std::string& enclave) {
  if (enclave == enclave_name(Role::ground)) return {Role::ground, -1};
  if (enclave == enclave_name(Role::listener)) return {Role::listener, -1};
  for (int id = 0; id < kMaxEndcaps; ++id) {
    if (enclave == enclave_name(Role::endcap, id)) return {Role::endcap, id};
  }
  throw DdsError("enclave '" + enclave + "': not one of the project's (/tensegrity/ground, endcap_00..11, listener)");
}

std::string permission_rules(const std::string& enclave) {
  const Identity who = identity_of(enclave);
  std::vector<std::string> publish, subscribe;
  for (const TopicSpec& t : kAllTopics) {
    if (may_publish(who.role, t)) publish.emplace_back(t.name);
    if (may_subscribe(who.role, t)) subscribe.emplace_back(t.name);
  }
  // Partitions bind an end cap's identity to its id: it writes its reports only in
  // its own partition (msgs/endcap_writers.hpp); the ground reads every end cap's;
  // orders travel in the default partition ("<partition/>" is the empty name).
  std::string publish_partitions = "<partitions><partition/></partitions>";
  std::string subscribe_partitions = "<partitions><partition/></partitions>";
  switch (who.role) {
    case Role::endcap:
      publish_partitions = "<partitions><partition>" + endcap_partition(who.endcap_id) + "</partition></partitions>";
      break;
    case Role::ground:
      subscribe_partitions =
          std::string("<partitions><partition>") + kEveryEndcapPartition + "</partition></partitions>";
      break;
    case Role::listener:
      // What a ROS 2 node publishes of its own (graph, log, parameters, services),
      // so that a node given this enclave can start and listen.
      publish = {"ros_discovery_info", "rt/rosout", "rt/parameter_events", "rq/*", "rr/*"};
      subscribe = {"*"};
      subscribe_partitions =
          std::string("<partitions><partition/><partition>") + kEveryEndcapPartition + "</partition></partitions>";
      break;
  }
  std::string rule = std::string("<allow_rule>") + kDomains;
  if (!publish.empty()) rule += "<publish>" + topic_list(publish) + publish_partitions + "</publish>";
  if (!subscribe.empty()) rule += "<subscribe>" + topic_list(subscribe) + subscribe_partitions + "</subscribe>";
  return rule + "</allow_rule>";
}

std::string permissions_xml(const std::string& enclave, const std::string& not_before, const std::string& not_after) {
  const std::string rule = permission_rules(enclave);
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-Security/20170801/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name=")" +
         enclave + R"(">
      <subject_name>)" +
         subject_name(enclave) + R"(</subject_name>
      <validity><not_before>)" +
         not_before + "</not_before><not_after>" + not_after + R"(</not_after></validity>
      )" +
         rule + R"(
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
)";
}

}  // namespace tensegrity::msgs
