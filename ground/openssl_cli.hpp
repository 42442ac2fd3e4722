// SPDX-License-Identifier: Apache-2.0
// Debian's `openssl` command, run without a shell: the keystore's keys,
// certificates, signatures and revocation list (ground/keystore.hpp says why the
// command and not the library's builders).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace tensegrity::ground {

// Runs `openssl ARGS...`, its output into `log`; throws KeystoreError with the
// log's text when it fails.
void openssl(std::vector<std::string> args, const std::filesystem::path& log);

// A new ECDSA P-256 key and a certificate for `enclave` ("CN=<enclave name>")
// signed by the keystore's CA at `root`, written as `out_dir`/key.pem (0600) and
// cert.pem. `serial`: decimal or 0x-prefixed hex.
void issue_identity(const std::filesystem::path& root, const std::string& enclave, const std::filesystem::path& out_dir,
                    const std::string& serial, int valid_days, const std::filesystem::path& log);

}  // namespace tensegrity::ground
