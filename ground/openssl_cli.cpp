// SPDX-License-Identifier: Apache-2.0
#include "ground/openssl_cli.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>

#include "ground/keystore.hpp"

extern char** environ;

namespace tensegrity::ground {

// Runs `openssl ARGS...` (no shell), its output into `log`; throws with the log's
// text when it fails.
void openssl(std::vector<std::string> args, const std::filesystem::path& log) {
  args.insert(args.begin(), "openssl");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, "openssl", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw KeystoreError(std::string("cannot run openssl (Debian package openssl): ") + std::strerror(rc));
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  std::ifstream in(log);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string cmd;
  for (std::size_t i = 0; i + 1 < argv.size(); ++i) cmd += std::string(i ? " " : "") + argv[i];
  throw KeystoreError(cmd + " failed:\n" + text);
}

namespace {
// "/tensegrity/ground" -> "/CN=\/tensegrity\/ground" (openssl -subj escapes '/').
std::string subj(const std::string& enclave) {
  std::string out = "/CN=";
  for (char c : enclave) out += (c == '/') ? std::string("\\/") : std::string(1, c);
  return out;
}
}  // namespace

void issue_identity(const std::filesystem::path& root, const std::string& enclave, const std::filesystem::path& out_dir,
                    const std::string& serial, int valid_days, const std::filesystem::path& log) {
  namespace fs = std::filesystem;
  const fs::path ca_cert = root / "public" / "ca.cert.pem", ca_key = root / "private" / "ca.key.pem";
  const std::string req = (out_dir / "req.pem").string();
  openssl({"req", "-new", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes", "-keyout",
           (out_dir / "key.pem").string(), "-out", req, "-subj", subj(enclave)},
          log);
  openssl({"x509", "-req", "-in", req, "-CA", ca_cert.string(), "-CAkey", ca_key.string(), "-set_serial", serial,
           "-days", std::to_string(valid_days), "-sha256", "-out", (out_dir / "cert.pem").string()},
          log);
  fs::remove(req);
  fs::permissions(out_dir / "key.pem", fs::perms::owner_read | fs::perms::owner_write);
}

}  // namespace tensegrity::ground
