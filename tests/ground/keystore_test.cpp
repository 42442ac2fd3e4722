// SPDX-License-Identifier: Apache-2.0
// `tensegrity security init`'s keystore: SROS2's layout, every enclave complete,
// documents signed by the CA (checked with openssl, as a second reader), private
// keys readable by their owner only, never half-written, safe to race for; a
// revoked identity on the CA's list in every enclave.
#include "ground/keystore.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <thread>

#include "msgs/security.hpp"

namespace tensegrity::ground {
namespace {

namespace fs = std::filesystem;

class Keystore : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("keystore_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  static int sh(const std::string& command) { return std::system((command + " >/dev/null 2>&1").c_str()); }
  fs::path dir_;
};

TEST_F(Keystore, InitMakesSros2sLayoutWithSignedDocuments) {
  const fs::path ks = dir_ / "ks";
  create_keystore(ks);
  EXPECT_TRUE(keystore_complete(ks));
  EXPECT_TRUE(fs::exists(ks / "public" / "ca.cert.pem"));
  EXPECT_TRUE(fs::exists(ks / "public" / "identity_ca.cert.pem"));
  EXPECT_TRUE(fs::exists(ks / "private" / "permissions_ca.key.pem"));
  EXPECT_TRUE(fs::exists(ks / "enclaves" / "governance.p7s"));
  const fs::path ca = ks / "public" / "ca.cert.pem";
  for (const std::string& enclave : msgs::all_enclaves()) {
    SCOPED_TRACE(enclave);
    const fs::path e = msgs::enclave_dir(ks, enclave);
    for (const char* doc : {"permissions.p7s", "governance.p7s"}) {
      EXPECT_EQ(sh("openssl smime -verify -in " + (e / doc).string() + " -CAfile " + ca.string()), 0) << doc;
    }
    EXPECT_EQ(sh("openssl verify -CAfile " + ca.string() + " " + (e / "cert.pem").string()), 0);
    // The certificate's subject is the one the permissions grant names.
    EXPECT_EQ(sh("openssl x509 -in " + (e / "cert.pem").string() +
                 " -noout -subject -nameopt RFC2253 | grep -qx 'subject=" + msgs::subject_name(enclave) + "'"),
              0);
    EXPECT_EQ(fs::status(e / "key.pem").permissions() & (fs::perms::group_all | fs::perms::others_all),
              fs::perms::none);
  }
  EXPECT_EQ(
      sh("openssl smime -verify -in " + (msgs::enclave_dir(ks, "/tensegrity/ground") / "permissions.p7s").string() +
         " -CAfile " + ca.string() + " | grep -q 'rt/tensegrity/command'"),
      0);
}

TEST_F(Keystore, RevokingListsTheOldCertificateEverywhereAndIssuesANewOne) {
  const fs::path ks = dir_ / "ks";
  create_keystore(ks);
  const std::string e3 = msgs::enclave_name(msgs::Role::endcap, 3), e7 = msgs::enclave_name(msgs::Role::endcap, 7);
  const fs::path old3 = dir_ / "old3.pem", old7 = dir_ / "old7.pem";
  fs::copy_file(msgs::enclave_dir(ks, e3) / "cert.pem", old3);
  fs::copy_file(msgs::enclave_dir(ks, e7) / "cert.pem", old7);
  const Revocation first = revoke_enclave(ks, e3);
  const Revocation second = revoke_enclave(ks, e7);
  EXPECT_EQ(first.revoked_total, 1);
  EXPECT_EQ(second.revoked_total, 2) << "a revocation must add to the list, not replace it";
  EXPECT_NE(first.new_serial, first.revoked_serial);
  const std::string ca = (ks / "public" / "ca.cert.pem").string();
  const std::string crl = (ks / "public" / "crl.pem").string();
  const std::string check = "openssl verify -crl_check -CAfile " + ca + " -CRLfile " + crl + " ";
  EXPECT_NE(sh(check + old3.string()), 0) << "the lost board's certificate still verifies";
  EXPECT_NE(sh(check + old7.string()), 0);
  EXPECT_EQ(sh(check + (msgs::enclave_dir(ks, e3) / "cert.pem").string()), 0) << "the new certificate";
  EXPECT_EQ(sh(check + (msgs::enclave_dir(ks, msgs::enclave_name(msgs::Role::ground)) / "cert.pem").string()), 0);
  // The new key is the new certificate's, and private.
  const std::string e3dir = msgs::enclave_dir(ks, e3).string();
  EXPECT_EQ(sh("test \"$(openssl x509 -in " + e3dir + "/cert.pem -noout -pubkey)\" = \"$(openssl pkey -in " + e3dir +
               "/key.pem -pubout)\""),
            0);
  EXPECT_EQ(fs::status(msgs::enclave_dir(ks, e3) / "key.pem").permissions() & fs::perms::others_all, fs::perms::none);
  std::ifstream list_in(crl);
  const std::string list((std::istreambuf_iterator<char>(list_in)), {});
  for (const std::string& enclave : msgs::all_enclaves()) {
    std::ifstream in(msgs::enclave_dir(ks, enclave) / "crl.pem");
    EXPECT_EQ(std::string((std::istreambuf_iterator<char>(in)), {}), list) << enclave << ": not the current list";
  }
  EXPECT_TRUE(keystore_complete(ks));
  EXPECT_THROW(revoke_enclave(ks, "/tensegrity/endcap_12"), KeystoreError);
  // A run that failed after listing but before the swap left the old certificate
  // in place: a rerun finishes the job instead of stopping at "already revoked".
  const fs::path e7dir = msgs::enclave_dir(ks, e7);
  fs::copy_file(old7, e7dir / "cert.pem", fs::copy_options::overwrite_existing);
  const Revocation rerun = revoke_enclave(ks, e7);
  EXPECT_EQ(rerun.revoked_total, 2);
  EXPECT_EQ(sh(check + (e7dir / "cert.pem").string()), 0);
}

TEST_F(Keystore, AnExistingKeystoreIsKeptUnlessReplaced) {
  const fs::path ks = dir_ / "ks";
  create_keystore(ks);
  std::ifstream before(ks / "public" / "ca.cert.pem");
  const std::string ca_before((std::istreambuf_iterator<char>(before)), {});
  EXPECT_THROW(create_keystore(ks), KeystoreError);
  EXPECT_FALSE(ensure_keystore(ks)) << "complete: kept";
  KeystoreOptions replace;
  replace.replace = true;
  create_keystore(ks, replace);
  std::ifstream after(ks / "public" / "ca.cert.pem");
  EXPECT_NE(ca_before, std::string((std::istreambuf_iterator<char>(after)), {})) << "a new CA";
  EXPECT_TRUE(keystore_complete(ks));
}

TEST_F(Keystore, AnIncompleteFolderIsRefusedNotFilledIn) {
  const fs::path ks = dir_ / "ks";
  fs::create_directories(ks / "enclaves");
  std::ofstream(ks / "enclaves" / "stray.txt") << "x";
  EXPECT_THROW(ensure_keystore(ks), KeystoreError);
}

// A keystore whose grants are not this version's (made before end caps published in
// their own partitions, or tampered with) is named with the fix, never used: its end
// caps could not create their writers.
TEST_F(Keystore, AnotherVersionsPermissionsAreNamedWithTheFix) {
  const fs::path ks = dir_ / "ks";
  create_keystore(ks);
  EXPECT_EQ(keystore_problem(ks), "");
  const fs::path e3 = msgs::enclave_dir(ks, msgs::enclave_name(msgs::Role::endcap, 3));
  const fs::path e5 = msgs::enclave_dir(ks, msgs::enclave_name(msgs::Role::endcap, 5));
  fs::copy_file(e5 / "permissions.p7s", e3 / "permissions.p7s", fs::copy_options::overwrite_existing);
  const std::string problem = keystore_problem(ks);
  EXPECT_NE(problem.find((e3 / "permissions.p7s").string()), std::string::npos) << problem;
  EXPECT_NE(problem.find("security init " + ks.string() + " --force"), std::string::npos) << problem;
  EXPECT_FALSE(keystore_complete(ks));
  try {
    ensure_keystore(ks);
    FAIL() << "a keystore with another version's grants was used";
  } catch (const KeystoreError& e) {
    EXPECT_NE(std::string(e.what()).find("endcap_03"), std::string::npos) << e.what();
  }
}

TEST_F(Keystore, ProcessesRacingToCreateOneAllGetTheSameComplete) {
  const fs::path ks = dir_ / "race";
  std::atomic<int> created{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < 3; ++i) {
    threads.emplace_back([&] { created += ensure_keystore(ks) ? 1 : 0; });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(created.load(), 1);
  EXPECT_TRUE(keystore_complete(ks));
  int leftovers = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) leftovers += entry.path() != ks ? 1 : 0;
  EXPECT_EQ(leftovers, 0) << "staging folders removed";
}

}  // namespace
}  // namespace tensegrity::ground
