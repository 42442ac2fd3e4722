// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/checkpoint.hpp"

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <system_error>

#include "format/atomic_file.hpp"
#include "sim/evolve/json_integer.hpp"

namespace tensegrity::sim::evolve {
namespace {

constexpr const char* kFormat = "tensegrity-evolve-checkpoint/1";

nlohmann::json stats_to_json(const GenerationStats& s) {
  return {{"generation", s.generation},      {"episodes", s.episodes},         {"teams", s.teams},
          {"infeasible", s.infeasible},      {"best_score_m", s.best_score_m}, {"mean_score_m", s.mean_score_m},
          {"best_so_far_m", s.best_so_far_m}};
}

GenerationStats stats_from_json(const nlohmann::json& j) {
  GenerationStats s;
  s.generation = json_integer<int>(j, "generation");
  s.episodes = json_integer<std::int64_t>(j, "episodes");
  s.teams = json_integer<int>(j, "teams");
  s.infeasible = json_integer<int>(j, "infeasible");
  s.best_score_m = j.at("best_score_m").get<double>();
  s.mean_score_m = j.at("mean_score_m").get<double>();
  s.best_so_far_m = j.at("best_so_far_m").get<double>();
  return s;
}

}  // namespace

std::string checkpoint_to_json(const EvolveConfig& config, const CoevolutionState& state) {
  nlohmann::json populations = nlohmann::json::array();
  for (const auto& population : state.populations) {
    nlohmann::json members = nlohmann::json::array();
    for (const auto& m : population) members.push_back({{"rest_lengths_m", m.rest_lengths_m}, {"history", m.history}});
    populations.push_back(std::move(members));
  }
  nlohmann::json curve = nlohmann::json::array();
  for (const auto& s : state.curve) curve.push_back(stats_to_json(s));
  nlohmann::json best = nullptr;
  if (state.best.found) {
    best = {{"rest_lengths_m", state.best.team.rest_lengths_m},
            {"score_m", state.best.score_m},
            {"feasible", state.best.feasible},
            {"episode", state.best.episode},
            {"generation", state.best.generation}};
  }
  // nlohmann writes doubles in the shortest form that reads back to the same bits,
  // which is what makes a resumed run identical to an uninterrupted one.
  const nlohmann::json j = {{"format", kFormat},
                            {"config", config_to_json(config)},
                            {"generation", state.generation},
                            {"episodes", state.episodes},
                            {"infeasible_episodes", state.infeasible_episodes},
                            {"rng_state", state.rng_state},
                            {"populations", std::move(populations)},
                            {"curve", std::move(curve)},
                            {"best", std::move(best)}};
  return j.dump(1) + "\n";
}

Checkpoint parse_checkpoint(const std::string& text, const std::string& source) {
  try {
    const nlohmann::json j = nlohmann::json::parse(text);
    if (!j.is_object() || j.value("format", "") != kFormat) {
      throw CheckpointError(source + ": not a " + std::string(kFormat) + " file");
    }
    Checkpoint cp;
    cp.config = config_from_json(j.at("config"));
    CoevolutionState& s = cp.state;
    s.generation = json_integer<int>(j, "generation");
    s.episodes = json_integer<std::int64_t>(j, "episodes");
    s.infeasible_episodes = json_integer<std::int64_t>(j, "infeasible_episodes");
    s.rng_state = j.at("rng_state").get<std::string>();
    for (const auto& population : j.at("populations")) {
      auto& members = s.populations.emplace_back();
      for (const auto& m : population) {
        members.push_back(
            Member{m.at("rest_lengths_m").get<std::vector<double>>(), m.at("history").get<std::vector<double>>()});
      }
    }
    for (const auto& g : j.at("curve")) s.curve.push_back(stats_from_json(g));
    const auto& best = j.at("best");
    if (!best.is_null()) {
      s.best.found = true;
      s.best.team.rest_lengths_m = best.at("rest_lengths_m").get<std::vector<std::vector<double>>>();
      s.best.score_m = best.at("score_m").get<double>();
      s.best.feasible = best.at("feasible").get<bool>();
      s.best.episode = json_integer<std::int64_t>(best, "episode", "best.episode");
      s.best.generation = json_integer<int>(best, "generation", "best.generation");
    }
    // Shape, limits and the engine state are checked the way a resume will use them.
    (void)Coevolution(cp.config, s);
    return cp;
  } catch (const CheckpointError&) {
    throw;
  } catch (const std::exception& e) {
    throw CheckpointError(source + ": " + e.what());
  }
}

void save_checkpoint(const std::filesystem::path& dir, const EvolveConfig& config, const CoevolutionState& state) {
  std::filesystem::create_directories(dir);
  const std::string text = checkpoint_to_json(config, state);
  const auto current = dir / kCheckpointFile;
  const auto previous = dir / kPreviousCheckpointFile;
  const auto tmp = dir / (std::string(kCheckpointFile) + ".new");
  // Write the new one completely first; then the current becomes the previous and
  // the new one the current. Killed between the two renames, the directory holds
  // only the previous, which load_checkpoint then uses: nothing is lost but the
  // generation in flight, which a resume recomputes identically.
  format::write_file_atomic(tmp, text);
  std::error_code ec;
  if (std::filesystem::exists(current, ec)) std::filesystem::rename(current, previous);
  std::filesystem::rename(tmp, current);
  format::fsync_directory(dir);
}

bool checkpoint_exists(const std::filesystem::path& dir) {
  std::error_code ec;
  return std::filesystem::exists(dir / kCheckpointFile, ec) ||
         std::filesystem::exists(dir / kPreviousCheckpointFile, ec);
}

namespace {

std::optional<std::string> read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

std::optional<LoadedCheckpoint> load_checkpoint(const std::filesystem::path& dir, const EvolveConfig& expected) {
  std::vector<std::string> problems;
  for (const char* name : {kCheckpointFile, kPreviousCheckpointFile}) {
    const auto path = dir / name;
    const auto text = read_file(path);
    if (!text) continue;
    Checkpoint cp;
    try {
      cp = parse_checkpoint(*text, path.string());
    } catch (const CheckpointError& e) {
      problems.emplace_back(e.what());
      continue;
    }
    // A larger episode budget continues the run: the budget only says when to stop,
    // so the result equals an uninterrupted run with the larger budget, as long as
    // no generation so far was cut short by the old budget.
    EvolveConfig as_saved = expected;
    const bool whole_generations = cp.state.episodes == std::int64_t{cp.state.generation} * cp.config.teams;
    if (expected.episodes > cp.config.episodes && whole_generations) as_saved.episodes = cp.config.episodes;
    const auto diffs = config_differences(cp.config, as_saved);
    if (!diffs.empty()) {
      std::string message = path.string() + ": made with another config; refusing to resume (checkpoint -> requested):";
      for (const auto& d : diffs) message += "\n  " + d;
      throw CheckpointError(message);
    }
    LoadedCheckpoint loaded{std::move(cp.state), path, {}};
    for (const auto& p : problems) loaded.warnings.push_back(p + "; using " + path.string() + " instead");
    return loaded;
  }
  if (problems.empty()) return std::nullopt;
  std::string message = "no usable checkpoint in " + dir.string() + ":";
  for (const auto& p : problems) message += "\n  " + p;
  throw CheckpointError(message);
}

}  // namespace tensegrity::sim::evolve
