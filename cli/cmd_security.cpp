// SPDX-License-Identifier: Apache-2.0
// `tensegrity security init DIR`: a DDS Security keystore (ground/keystore.hpp) with
// the project CA, the ground, 12 end-cap and listener enclaves and their signed
// governance and permissions; `security check DIR` says whether one is complete;
// `security revoke NAME DIR` withdraws a lost board's identity.
#include <cstdio>

#include "cli/commands.hpp"
#include "ground/keystore.hpp"
#include "msgs/security.hpp"

namespace tensegrity::cli {
namespace {

void add_revoke(CLI::App& security) {
  struct RevokeArgs {
    std::string name;
    std::string dir;
    int days = 3650;
  };
  auto args = std::make_shared<RevokeArgs>();
  CLI::App* cmd = security.add_subcommand(
      "revoke",
      "Withdraw an identity (a lost or stolen board): revoke its certificate, put the CA's revocation list "
      "(crl.pem) in every enclave, and give the enclave a new identity for its replacement");
  cmd->add_option("name", args->name, "Enclave: ground, listener or endcap_NN (or /tensegrity/...)")->required();
  cmd->add_option("dir", args->dir, "Keystore folder (default as for init)");
  cmd->add_option("--days", args->days, "Validity of the new certificate, days")
      ->check(CLI::Range(1, 36500))
      ->capture_default_str();
  cmd->callback([args] {
    const std::filesystem::path dir = args->dir.empty() ? msgs::default_keystore() : std::filesystem::path(args->dir);
    const std::string enclave = args->name.starts_with('/') ? args->name : "/tensegrity/" + args->name;
    ground::Revocation r;
    try {
      r = ground::revoke_enclave(dir, enclave, args->days);
    } catch (const ground::KeystoreError& e) {
      throw CommandError(ExitCode::failure, e.what());
    }
    std::printf("revoked %s certificate serial %s (%d on the list); its new serial %s\n", enclave.c_str(),
                r.revoked_serial.c_str(), r.revoked_total, r.new_serial.c_str());
    std::printf(
        "copy crl.pem (%s/public/crl.pem, the same in every enclave) to every board, and the new %s enclave "
        "to the replacement board, and restart what runs (consoles, HIL, end caps): a participant reads the list when "
        "it starts, and until then it still accepts the old identity\n",
        dir.string().c_str(), enclave.c_str());
  });
}

}  // namespace

void add_security_command(CLI::App& app) {
  CLI::App* security = app.add_subcommand("security", "DDS Security keystores (SROS2 layout)");
  security->require_subcommand(1);

  struct InitArgs {
    std::string dir;
    ground::KeystoreOptions options;
  };
  auto init = std::make_shared<InitArgs>();
  CLI::App* cmd = security->add_subcommand(
      "init", "Create a keystore: project CA, ground / endcap_00..11 / listener enclaves, signed documents");
  cmd->add_option("dir", init->dir,
                  "Keystore folder (default: TENSEGRITY_KEYSTORE, else ~/.local/share/tensegrity/keystore)");
  cmd->add_option("--days", init->options.valid_days, "Validity of certificates and permissions, days")
      ->check(CLI::Range(1, 36500))
      ->capture_default_str();
  cmd->add_flag("--force", init->options.replace,
                "Replace an existing keystore (a new CA: every end cap needs its enclave again)");
  cmd->callback([init] {
    const std::filesystem::path dir = init->dir.empty() ? msgs::default_keystore() : std::filesystem::path(init->dir);
    try {
      ground::create_keystore(dir, init->options);
    } catch (const ground::KeystoreError& e) {
      throw CommandError(ExitCode::failure, e.what());
    }
    std::printf("keystore %s: CA, %zu enclaves (ground, endcap_00..11, listener), valid %d days\n",
                dir.string().c_str(), msgs::all_enclaves().size(), init->options.valid_days);
    std::printf("end cap N on its board: copy %s/enclaves/tensegrity/endcap_NN and set \"dds_keystore\"\n",
                dir.string().c_str());
  });

  auto check_dir = std::make_shared<std::string>();
  CLI::App* check = security->add_subcommand(
      "check", "Exit 0 when a keystore has every enclave's files and this version's permissions");
  check->add_option("dir", *check_dir, "Keystore folder (default as for init)");
  check->callback([check_dir] {
    const std::filesystem::path dir = check_dir->empty() ? msgs::default_keystore() : std::filesystem::path(*check_dir);
    if (const std::string problem = ground::keystore_problem(dir); !problem.empty())
      throw CommandError(ExitCode::failure, problem);
    std::printf("keystore %s: complete (%zu enclaves)\n", dir.string().c_str(), msgs::all_enclaves().size());
  });
  add_revoke(*security);
}

}  // namespace tensegrity::cli
