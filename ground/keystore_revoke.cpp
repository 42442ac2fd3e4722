// SPDX-License-Identifier: Apache-2.0
// `tensegrity security revoke`: the CA's revocation list, kept with `openssl ca`'s
// own database so that each revocation adds to the list instead of replacing it.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

#include "ground/keystore.hpp"
#include "ground/openssl_cli.hpp"
#include "msgs/security.hpp"

namespace tensegrity::ground {

namespace fs = std::filesystem;

namespace {

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out) throw KeystoreError("cannot write " + path.string());
}

// A file replaced whole: readers (a participant starting now) see the old or the new.
void replace_file(const fs::path& from, const fs::path& to) {
  const fs::path tmp = to.string() + ".new";
  fs::copy_file(from, tmp, fs::copy_options::overwrite_existing);
  fs::rename(tmp, to);
}

// The database `openssl ca` keeps (index of revoked certificates, CRL number) and a
// configuration naming it.
// The list itself is valid this long whatever the certificates' validity: a list
// past its next-update date would stop every participant that holds it.
constexpr int kListValidDays = 3650;

fs::path ca_database(const fs::path& dir) {
  const fs::path db = dir / "private" / "ca.db";
  fs::create_directories(db);
  fs::permissions(db, fs::perms::owner_all);
  if (!fs::exists(db / "index.txt")) write_text(db / "index.txt", "");
  if (!fs::exists(db / "crlnumber")) write_text(db / "crlnumber", "1000\n");
  write_text(db / "openssl.cnf",
             "[ ca ]\ndefault_ca = tensegrity\n[ tensegrity ]\ndatabase = " + (db / "index.txt").string() +
                 "\ncrlnumber = " + (db / "crlnumber").string() +
                 "\ndefault_md = sha256\ndefault_crl_days = " + std::to_string(kListValidDays) + "\n");
  return db;
}

std::string serial_of(const fs::path& cert, const fs::path& log) {
  openssl({"x509", "-in", cert.string(), "-noout", "-serial"}, log);
  std::string text = read_text(log);  // "serial=0A\n"
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos) throw KeystoreError(cert.string() + ": openssl printed no serial");
  text = text.substr(eq + 1);
  text.erase(std::remove_if(text.begin(), text.end(), [](char c) { return c == '\n' || c == '\r'; }), text.end());
  return text;
}

std::string random_serial() {
  std::random_device rd;
  char text[32];
  // 62 random bits: positive, distinct from init's small serials with overwhelming odds.
  const unsigned long long v = ((static_cast<unsigned long long>(rd()) << 32) | rd()) >> 2;
  std::snprintf(text, sizeof text, "0x%016llX", v | (1ULL << 60));
  return text;
}

}  // namespace

Revocation revoke_enclave(const fs::path& dir_in, const std::string& enclave, int valid_days) {
  const fs::path dir = fs::absolute(dir_in).lexically_normal();
  if (const std::string problem = keystore_problem(dir); !problem.empty()) throw KeystoreError(problem);
  try {
    (void)msgs::identity_of(enclave);
  } catch (const std::exception& e) {
    throw KeystoreError(e.what());
  }
  const fs::path db = ca_database(dir);
  const fs::path log = db / "openssl.log", cnf = db / "openssl.cnf";
  const std::string ca_cert = (dir / "public" / "ca.cert.pem").string();
  const std::string ca_key = (dir / "private" / "ca.key.pem").string();
  const fs::path enclave_dir = msgs::enclave_dir(dir, enclave);

  Revocation out;
  out.revoked_serial = serial_of(enclave_dir / "cert.pem", log);
  // The replacement identity first, aside: if anything below fails, the enclave
  // still holds a matching key and certificate, and a rerun finishes the job.
  const fs::path fresh = db / "reissue";
  fs::remove_all(fresh);
  fs::create_directories(fresh);
  out.new_serial = random_serial();
  issue_identity(dir, enclave, fresh, out.new_serial, valid_days, log);
  // Already on the list (a rerun after a failure): not revoked twice, which openssl refuses.
  const std::string listed = "\t" + out.revoked_serial + "\tunknown\t";
  if (read_text(db / "index.txt").find(listed) == std::string::npos) {
    openssl({"ca", "-config", cnf.string(), "-keyfile", ca_key, "-cert", ca_cert, "-revoke",
             (enclave_dir / "cert.pem").string()},
            log);
  }
  openssl({"ca", "-config", cnf.string(), "-keyfile", ca_key, "-cert", ca_cert, "-gencrl", "-out",
           (db / "crl.pem").string()},
          log);
  replace_file(db / "crl.pem", dir / "public" / "crl.pem");
  for (const std::string& name : msgs::all_enclaves()) {
    replace_file(dir / "public" / "crl.pem", msgs::enclave_dir(dir, name) / "crl.pem");
  }
  // Key and certificate change together: the key first (a participant started in
  // between fails its own check and says so), the certificate right after.
  fs::rename(fresh / "key.pem", enclave_dir / "key.pem");
  fs::rename(fresh / "cert.pem", enclave_dir / "cert.pem");
  fs::remove_all(fresh);
  const std::string index = read_text(db / "index.txt");
  out.revoked_total = static_cast<int>(std::count(index.begin(), index.end(), '\n'));
  return out;
}

}  // namespace tensegrity::ground
