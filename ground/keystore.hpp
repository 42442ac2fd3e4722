// SPDX-License-Identifier: Apache-2.0
// A DDS Security keystore laid out as SROS2's (`ros2 security create_keystore` +
// `create_enclave`), so ROS 2 users recognise it and a ROS 2 node given the listener
// enclave can read the robot's topics:
//   KEYSTORE/public/ca.cert.pem (+ identity_ca / permissions_ca links)
//   KEYSTORE/private/ca.key.pem (+ links; 0700)
//   KEYSTORE/enclaves/governance.xml, governance.p7s
//   KEYSTORE/enclaves/tensegrity/<name>/cert.pem key.pem identity_ca.cert.pem
//       permissions_ca.cert.pem governance.p7s permissions.xml permissions.p7s
// One project CA (ECDSA P-256) is both the identity and the permissions CA. Keys,
// certificates and S/MIME signatures are made by Debian's `openssl` command: the
// library's X.509 and PKCS#7 builders would be a few hundred lines that this one
// well-kept tool already is. Enclave folders hold copies, not links, so one can be
// copied to an end cap's board as it is. docs/guide/security.md.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

namespace tensegrity::ground {

class KeystoreError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct KeystoreOptions {
  int valid_days = 3650;
  bool replace = false;  // replace an existing keystore (new CA: every board needs its enclave again)
};

// Creates a complete keystore at `dir`: built in a sibling folder and renamed into
// place, so a reader never sees half of one. Throws KeystoreError if `dir` exists
// (unless options.replace) or openssl fails (its message included).
void create_keystore(const std::filesystem::path& dir, const KeystoreOptions& options = {});

// Empty when every enclave of the project (ground, 12 end caps, listener) has all
// its files and the permissions this version grants; else what is wrong, with the fix.
std::string keystore_problem(const std::filesystem::path& dir);
bool keystore_complete(const std::filesystem::path& dir);

// The keystore at `dir`, created first if it is not there. Safe when several
// processes race to create the same one (the first rename wins, the rest use it).
// Returns true when this call created it.
bool ensure_keystore(const std::filesystem::path& dir);

// Withdraws the identity of `enclave` ("/tensegrity/endcap_05"), as for a lost or
// stolen board: its certificate goes on the CA's revocation list (a database in
// KEYSTORE/private/ca.db, the signed list in KEYSTORE/public/crl.pem), the list is
// copied into every enclave as crl.pem (SROS2's name; Fast DDS's identity_crl), and
// the enclave gets a new key and certificate for its replacement board. Every
// participant started with the new crl.pem refuses the old certificate; boards must
// get the file (it is the same in every enclave). Safe to rerun after a failure.
// Throws KeystoreError.
struct Revocation {
  std::string revoked_serial;  // as openssl prints it, hex
  std::string new_serial;
  int revoked_total = 0;  // certificates on the list now
};
Revocation revoke_enclave(const std::filesystem::path& dir, const std::string& enclave, int valid_days = 3650);

}  // namespace tensegrity::ground
