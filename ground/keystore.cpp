// SPDX-License-Identifier: Apache-2.0
#include "ground/keystore.hpp"

#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "ground/openssl_cli.hpp"
#include "msgs/security.hpp"

namespace tensegrity::ground {

namespace fs = std::filesystem;

namespace {

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out) throw KeystoreError("cannot write " + path.string());
}

std::string utc(std::time_t t) {
  std::tm tm{};
  ::gmtime_r(&t, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &tm);
  return text;
}

void sign(const fs::path& in, const fs::path& out, const fs::path& ca_cert, const fs::path& ca_key,
          const fs::path& log) {
  // S/MIME with the document as text, as SROS2 signs them and Fast DDS reads them.
  openssl({"smime", "-sign", "-text", "-in", in.string(), "-out", out.string(), "-signer", ca_cert.string(), "-inkey",
           ca_key.string()},
          log);
}

void make_enclave(const fs::path& root, const std::string& enclave, int serial, const KeystoreOptions& options,
                  const fs::path& log) {
  const fs::path dir = msgs::enclave_dir(root, enclave);
  const fs::path ca_cert = root / "public" / "ca.cert.pem", ca_key = root / "private" / "ca.key.pem";
  fs::create_directories(dir);
  issue_identity(root, enclave, dir, std::to_string(serial), options.valid_days, log);
  fs::copy_file(ca_cert, dir / "identity_ca.cert.pem");
  fs::copy_file(ca_cert, dir / "permissions_ca.cert.pem");
  fs::copy_file(root / "enclaves" / "governance.p7s", dir / "governance.p7s");
  // Valid from a day back: an end cap's clock a little behind the ground's must not
  // find its own permissions "not yet valid".
  const std::time_t now = std::time(nullptr);
  write_text(dir / "permissions.xml",
             msgs::permissions_xml(enclave, utc(now - 86400),
                                   utc(now + static_cast<std::time_t>(options.valid_days) * 86400)));
  sign(dir / "permissions.xml", dir / "permissions.p7s", ca_cert, ca_key, log);
}

void build(const fs::path& root, const KeystoreOptions& options) {
  const fs::path log = root / "openssl.log";
  fs::create_directories(root / "public");
  fs::create_directories(root / "private");
  fs::create_directories(root / "enclaves");
  fs::permissions(root / "private", fs::perms::owner_all);
  const fs::path ca_cert = root / "public" / "ca.cert.pem", ca_key = root / "private" / "ca.key.pem";
  // digitalSignature beside the CA usages: the CA itself signs the governance and
  // permissions (S/MIME), which a verifier otherwise refuses as the wrong purpose.
  openssl({"req",
           "-x509",
           "-newkey",
           "ec",
           "-pkeyopt",
           "ec_paramgen_curve:prime256v1",
           "-nodes",
           "-keyout",
           ca_key.string(),
           "-out",
           ca_cert.string(),
           "-days",
           std::to_string(options.valid_days),
           "-sha256",
           "-subj",
           "/CN=tensegrity keystore CA",
           "-addext",
           "basicConstraints=critical,CA:TRUE",
           "-addext",
           "keyUsage=critical,keyCertSign,cRLSign,digitalSignature"},
          log);
  for (const char* name : {"identity_ca", "permissions_ca"}) {
    fs::create_symlink("ca.cert.pem", root / "public" / (std::string(name) + ".cert.pem"));
    fs::create_symlink("ca.key.pem", root / "private" / (std::string(name) + ".key.pem"));
  }
  write_text(root / "enclaves" / "governance.xml", msgs::governance_xml());
  sign(root / "enclaves" / "governance.xml", root / "enclaves" / "governance.p7s", ca_cert, ca_key, log);
  int serial = 1;
  for (const std::string& enclave : msgs::all_enclaves()) make_enclave(root, enclave, serial++, options, log);
  fs::remove(log);
}

fs::path staging_dir(const fs::path& dir) {
  std::string templ = (dir.parent_path() / (dir.filename().string() + ".new-XXXXXX")).string();
  if (::mkdtemp(templ.data()) == nullptr) {
    throw KeystoreError("cannot create a folder beside " + dir.string() + ": " + std::strerror(errno));
  }
  return templ;
}

}  // namespace

std::string keystore_problem(const fs::path& dir) {
  for (const std::string& enclave : msgs::all_enclaves()) {
    const fs::path enclave_dir = msgs::enclave_dir(dir, enclave);
    try {
      msgs::check_enclave(msgs::enclave_files(enclave_dir));
    } catch (const msgs::DdsError& e) {
      return e.what();
    }
    // The signed document is what Fast DDS reads; the .xml beside it is its text.
    std::ifstream in(enclave_dir / "permissions.p7s");
    const std::string signed_text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (signed_text.find(msgs::permission_rules(enclave)) == std::string::npos) {
      return (enclave_dir / "permissions.p7s").string() +
             ": grants other rules than this version does (a keystore made by an older version: end caps now "
             "publish in their own partitions); recreate it with `tensegrity security init " +
             dir.string() + " --force` and copy each end cap its enclave again";
    }
  }
  return {};
}

bool keystore_complete(const fs::path& dir) { return keystore_problem(dir).empty(); }

void create_keystore(const fs::path& dir_in, const KeystoreOptions& options) {
  if (options.valid_days < 1)
    throw KeystoreError("valid_days = " + std::to_string(options.valid_days) + ": expected >= 1");
  const fs::path dir = fs::absolute(dir_in).lexically_normal();
  if (fs::exists(dir) && !options.replace) {
    throw KeystoreError(dir.string() +
                        " exists (pass --force to replace it: every end cap then needs its enclave again)");
  }
  fs::create_directories(dir.parent_path());
  const fs::path staging = staging_dir(dir);
  try {
    build(staging, options);
    if (options.replace && fs::exists(dir)) fs::remove_all(dir);
    fs::rename(staging, dir);
  } catch (...) {
    std::error_code ignored;
    fs::remove_all(staging, ignored);
    throw;
  }
}

bool ensure_keystore(const fs::path& dir_in) {
  const fs::path dir = fs::absolute(dir_in).lexically_normal();
  if (keystore_complete(dir)) return false;
  if (fs::exists(dir) && !fs::is_empty(dir)) {
    throw KeystoreError(dir.string() + " is not a usable tensegrity keystore: " + keystore_problem(dir));
  }
  fs::create_directories(dir.parent_path());
  const fs::path staging = staging_dir(dir);
  try {
    build(staging, KeystoreOptions{});
  } catch (...) {
    std::error_code ignored;
    fs::remove_all(staging, ignored);
    throw;
  }
  std::error_code ec;
  if (fs::exists(dir) && fs::is_empty(dir)) fs::remove(dir, ec);
  fs::rename(staging, dir, ec);
  if (!ec) return true;
  // Another process renamed its keystore into place first: use that one.
  fs::remove_all(staging, ec);
  if (!keystore_complete(dir)) throw KeystoreError("keystore " + dir.string() + " appeared incomplete");
  return false;
}

}  // namespace tensegrity::ground
