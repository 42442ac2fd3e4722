// SPDX-License-Identifier: Apache-2.0
// The seam between "the end caps are up" and "they play the policy": how a
// policy reaches the end caps and how they are told to start.
//
// Now: LocalProvisioner, the --start-on-boot style: each end cap's program gets
// `--policy FILE` (it validates, stores and loads its share) and starts playing
// as soon as its drives are enabled; the world stepper's start gate enables all
// drives in one tick, so all tables start in phase. A restarted end cap gets no
// --policy: it plays the one it stored.
// Later: a DDS provisioner (ground/: the `tensegrity upload` code path) gives no
// policy arguments, uploads in provision() (acknowledged per end cap) and sends
// the start command in start() with a common start time.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace tensegrity::hil {

class ProcessLauncher;

class Provisioner {
 public:
  virtual ~Provisioner() = default;
  virtual std::string name() const = 0;
  // Extra command-line arguments of end cap `endcap`'s program (restart: after a kill).
  virtual std::vector<std::string> endcap_arguments(int endcap, bool restart) const = 0;
  // Every end cap is up, its drives waiting at the start gate: deliver the policy.
  // Throws HilError naming the end caps that did not acknowledge it.
  virtual void provision(const ProcessLauncher& launcher) = 0;
  // Arrange the in-phase start (before the stepper opens the start gate).
  virtual void start(const ProcessLauncher& launcher) = 0;
};

class LocalProvisioner final : public Provisioner {
 public:
  explicit LocalProvisioner(std::filesystem::path policy) : policy_(std::move(policy)) {}
  std::string name() const override { return "local (--policy, --start-on-boot)"; }
  std::vector<std::string> endcap_arguments(int endcap, bool restart) const override;
  // The end cap logs "policy FILE loaded and stored" once its share passed validation.
  void provision(const ProcessLauncher& launcher) override;
  void start(const ProcessLauncher&) override {}  // start on boot + the start gate

 private:
  std::filesystem::path policy_;
};

}  // namespace tensegrity::hil
