// SPDX-License-Identifier: Apache-2.0
#pragma once
// The policy file (format "tensegrity-policy/1"): a periodic table of preferred rest
// lengths per cable, which end cap owns each cable, and where the policy came from.
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <optional>
#include <string>
#include <vector>

#include "core/table.hpp"
#include "robot/robot.hpp"

namespace tensegrity::sim {

class PolicyError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CablePolicy {
  int cable = 0;
  int owner = 0;
  std::vector<double> rest_lengths_m;  // `complexity` values
};

struct Provenance {
  std::string method;  // historical | leniency | average | hand
  std::uint64_t seed = 0;
  std::int64_t episodes = 0;
  double score_m = 0.0;
  std::string robot_hash;
  std::string created_by = "tensegrity";
  // The mutation step the coevolution bred with (its schedule: docs/guide/evolve.md), so that
  // method + seed + episodes + this reproduce the policy. sigma_m 0: not recorded.
  std::string mutation = "gaussian";  // the operator: gaussian | author
  double sigma_m = 0.0;
  double sigma_final_m = 0.0;
  std::int64_t anneal_start_episodes = 0;
  std::int64_t anneal_episodes = 0;
  // The coevolution's sizes (--population, --replace, --teams): the defaults have
  // changed, so a policy without them cannot say which it was bred with. 0: not recorded.
  int population = 0;
  int replace = 0;
  int teams = 0;
  // How the policy's struts turned in the episode that scored it (sim::EpisodeResult):
  // a gait must roll, not skate on spinning struts. endcaps_touched_ground -1: not recorded.
  double axial_spin_rms_rad_per_s = 0.0;
  double axial_spin_max_rad_per_s = 0.0;
  int endcaps_touched_ground = -1;
  // The closest two struts came, m (negative: they overlapped), and how long two
  // overlapped, s; absent in policies written before they were recorded.
  std::optional<double> min_strut_gap_m = std::nullopt;
  std::optional<double> strut_overlap_s = std::nullopt;
  // The heading the gait rolled in that episode, degrees in its start frame
  // (sim/start_frame.hpp; from the settled start, the world frame); absent: unknown.
  std::optional<double> heading_deg = std::nullopt;
  // For a symmetry's image of another policy (`tensegrity gaits mirror`): the
  // symmetry, as the image of the description's (x, y, z); empty otherwise.
  std::string symmetry = "";
};

struct Policy {
  std::string robot;
  double period_s = 0.0;
  int complexity = 0;
  std::vector<CablePolicy> cables;  // indexed by cable
  Provenance provenance;
};

// Parses and validates against `robot`: robot name, one entry per cable with its
// owner, `complexity` finite values within the rest-length limits, period > 0.
// Errors name the source and the field.
Policy parse_policy(const std::string& json_text, const Robot& robot, const std::string& source = "policy");
Policy load_policy(const std::filesystem::path& path, const Robot& robot);
std::string policy_to_json(const Policy& policy);
// The robot a policy file was made for, when no robot is given: robots/<its "robot">.json
// when that file exists, else the default robot (whose name check then says what is
// wrong). The policy names its robot, so playing it needs no --robot.
std::filesystem::path robot_path_for_policy(const std::filesystem::path& policy_path);
// Writes to a temporary file beside `path`, then renames: never a half-written policy.
void save_policy(const std::filesystem::path& path, const Policy& policy);

// The share of end cap `endcap`: its cables in increasing index, as the core plays it,
// by the end cap's own rule (format::endcap_table_of) and checked by its limits.
core::EndcapTable endcap_table(const Policy& policy, const Robot& robot, int endcap);

}  // namespace tensegrity::sim
