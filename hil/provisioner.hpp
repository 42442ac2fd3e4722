// SPDX-License-Identifier: Apache-2.0
// The seam between "the end caps are up" and "they play the policy": how a
// policy reaches the end caps and how they are told to start.
//
// LocalProvisioner, the --start-on-boot style: each end cap's program gets
// `--policy FILE` (it validates, stores and loads its share) and starts playing
// as soon as its drives are enabled; the world stepper's start gate enables all
// drives in one tick, so all tables start in phase. A restarted end cap gets no
// --policy: it plays the one it stored. No DDS at all (`--no-dds`).
//
// DdsProvisioner (dds_provisioner.hpp): what a real robot gets, over DDS; it needs
// the end caps running while it works, so the stepper holds them (needs_hold()).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace tensegrity::hil {

class ProcessLauncher;
class StartHandshake;

// How the host link came up (the DDS provisioner's; bench hil reports what
// DDS Security costs from it).
struct LinkTiming {
  bool dds = false;
  bool secured = false;      // DDS Security (a keystore's enclaves)
  double discovery_s = 0.0;  // every end cap's heartbeat with a synchronized clock
  double upload_s = 0.0;     // the policy upload, first send to the last acknowledgement
};

// How the host heard one end cap during the run (real time, dds): its heartbeat
// missing for 2 s or more, how often, how long in all, the longest (one still open at
// the run's end counts to the end).
struct HostHearing {
  std::uint64_t unheard = 0;
  double unheard_s = 0.0;
  double longest_unheard_s = 0.0;
};

class Provisioner {
 public:
  virtual ~Provisioner() = default;
  virtual std::string name() const = 0;
  // Extra command-line arguments of end cap `endcap`'s program (restart: after a kill).
  virtual std::vector<std::string> endcap_arguments(int endcap, bool restart) const = 0;

  // false: provision() and start() run while every end cap waits at the start
  // gate; opening the gate is physics step 0.
  // true: the gate opens first; deliver() runs on its own thread while the stepper
  // holds (drives enabled, physics frozen) and names physics step 0 through the
  // handshake. It throws on failure (the caller fails the handshake with it).
  virtual bool needs_hold() const { return false; }
  // Every end cap is up, its drives waiting at the start gate: deliver the policy.
  // Throws HilError naming the end caps that did not acknowledge it.
  virtual void provision(const ProcessLauncher& launcher) = 0;
  // Arrange the in-phase start (before the stepper opens the start gate).
  virtual void start(const ProcessLauncher& launcher) = 0;
  virtual void deliver(StartHandshake&) {}

  // Around WorldStepper::run (e.g. a thread that starts restarted end caps again).
  virtual void begin_run() {}
  virtual void end_run() {}
  // Whether the end caps run a DDS link to this host (cut_dds / restore_dds need one).
  virtual bool dds_link() const { return false; }
  // End cap `endcap` was just started again (kill/restart scenario), stepper's thread.
  virtual void on_restart(int) {}
  // What the provisioner did, one line each, for the run's log.
  virtual std::vector<std::string> log() const { return {}; }
  virtual LinkTiming link_timing() const { return {}; }
  // Per end cap; empty when the provisioner does not watch a link.
  virtual std::vector<HostHearing> host_hearing() const { return {}; }
};

class LocalProvisioner final : public Provisioner {
 public:
  explicit LocalProvisioner(std::filesystem::path policy) : policy_(std::move(policy)) {}
  std::string name() const override { return "local (--policy, --start-on-boot, no DDS)"; }
  std::vector<std::string> endcap_arguments(int endcap, bool restart) const override;
  // The end cap logs "policy FILE loaded and stored" once its share passed validation.
  void provision(const ProcessLauncher& launcher) override;
  void start(const ProcessLauncher&) override {}  // start on boot + the start gate

 private:
  std::filesystem::path policy_;
};

}  // namespace tensegrity::hil
