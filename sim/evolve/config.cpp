// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/config.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

#include "core/limits.hpp"
#include "sim/evolve/json_integer.hpp"

namespace tensegrity::sim::evolve {

const char* to_string(FitnessMethod method) {
  switch (method) {
    case FitnessMethod::historical: return "historical";
    case FitnessMethod::leniency: return "leniency";
    case FitnessMethod::average: return "average";
  }
  return "?";
}

FitnessMethod parse_fitness_method(const std::string& text) {
  if (text == "historical") return FitnessMethod::historical;
  if (text == "leniency") return FitnessMethod::leniency;
  if (text == "average") return FitnessMethod::average;
  throw ConfigError("unknown method '" + text + "' (historical, leniency or average)");
}

const char* to_string(Mutation mutation) {
  switch (mutation) {
    case Mutation::gaussian: return "gaussian";
    case Mutation::author: return "author";
  }
  return "?";
}

Mutation parse_mutation(const std::string& text) {
  if (text == "gaussian") return Mutation::gaussian;
  if (text == "author") return Mutation::author;
  throw ConfigError("unknown mutation '" + text + "' (author or gaussian)");
}

const char* to_string(SampleScore score) { return score == SampleScore::q25 ? "q25" : "mean"; }

SampleScore parse_sample_score(const std::string& text) {
  if (text == "mean") return SampleScore::mean;
  if (text == "q25") return SampleScore::q25;
  throw ConfigError("unknown sample score '" + text + "' (mean or q25)");
}

void validate(const EvolveConfig& c) {
  auto fail = [](const std::string& what) { throw ConfigError("evolve config: " + what); };
  if (c.population < 2) fail("population must be at least 2");
  if (c.teams < 1) fail("teams must be at least 1");
  // The copies come from the survivors: more than half would copy members that die.
  if (c.replace < 1 || c.replace > c.population / 2) fail("replace must be in 1..population/2");
  if (!(c.sigma_m >= 0.0) || !std::isfinite(c.sigma_m)) fail("sigma_m must be finite and >= 0");
  if (!(c.sigma_final_m >= 0.0) || !std::isfinite(c.sigma_final_m)) fail("sigma_final_m must be finite and >= 0");
  if (c.anneal_episodes < 0) fail("anneal_episodes must be >= 0");
  if (c.anneal_start_episodes < 0) fail("anneal_start_episodes must be >= 0");
  if (c.anneal_episodes > 0 && (c.sigma_m == 0.0) != (c.sigma_final_m == 0.0)) {
    fail("sigma_m and sigma_final_m must both be > 0 to anneal (the step changes geometrically)");
  }
  if (c.episodes < 1) fail("episodes must be at least 1");
  if (c.cables < 1) fail("cables must be at least 1");
  if (c.complexity < 1 || c.complexity > static_cast<int>(core::kMaxComplexity)) {
    fail("complexity must be in 1.." + std::to_string(core::kMaxComplexity));
  }
  if (!std::isfinite(c.min_rest_length_m) || !std::isfinite(c.max_rest_length_m) ||
      !(c.min_rest_length_m < c.max_rest_length_m)) {
    fail("rest-length limits must be finite with min < max");
  }
  if (!(c.period_s > 0.0) || !std::isfinite(c.period_s)) fail("period_s must be > 0");
  if (!(c.duration_s > 0.0) || !std::isfinite(c.duration_s)) fail("duration_s must be > 0");
  if (!(c.dt_s >= 0.0 && c.dt_s <= 0.01)) fail("dt_s must be in [0, 0.01] (0: the robot's step)");
  if (!(c.early_end_bar_m >= 0.0 && c.early_end_bar_m <= 1000.0)) fail("early_end_bar_m must be in [0, 1000]");
  if (c.early_end_bar_m > 0.0 && !(c.early_end_speed_m_per_s > 0.0 && c.early_end_speed_m_per_s <= 100.0)) {
    fail("early_end_speed_m_per_s must be in (0, 100] when early_end_bar_m is set");
  }
  if (!c.randomization.empty() && (c.randomize_k < 1 || c.randomize_k > kMaxRandomizeK)) {
    fail("randomize_k must be in 1.." + std::to_string(kMaxRandomizeK));
  }
}

double mutation_sigma_m(const EvolveConfig& c, std::int64_t episodes_done) {
  if (c.anneal_episodes <= 0 || c.sigma_m == c.sigma_final_m) return c.sigma_m;
  const std::int64_t into = episodes_done - c.anneal_start_episodes;
  if (into <= 0) return c.sigma_m;
  if (into >= c.anneal_episodes) return c.sigma_final_m;
  const double progress = static_cast<double>(into) / static_cast<double>(c.anneal_episodes);
  return c.sigma_m * std::pow(c.sigma_final_m / c.sigma_m, progress);
}

nlohmann::json config_to_json(const EvolveConfig& c) {
  nlohmann::json j{{"method", to_string(c.method)},
                   {"population", c.population},
                   {"teams", c.teams},
                   {"replace", c.replace},
                   {"mutation", to_string(c.mutation)},
                   {"sigma_m", c.sigma_m},
                   // Without annealing the final step is the step, whatever the field holds.
                   {"sigma_final_m", c.anneal_episodes > 0 ? c.sigma_final_m : c.sigma_m},
                   {"anneal_start_episodes", c.anneal_episodes > 0 ? c.anneal_start_episodes : 0},
                   {"anneal_episodes", c.anneal_episodes},
                   {"seed", c.seed},
                   {"episodes", c.episodes},
                   {"cables", c.cables},
                   {"complexity", c.complexity},
                   {"min_rest_length_m", c.min_rest_length_m},
                   {"max_rest_length_m", c.max_rest_length_m},
                   {"period_s", c.period_s},
                   {"duration_s", c.duration_s},
                   {"robot_name", c.robot_name},
                   {"robot_hash", c.robot_hash}};
  // Written only when set, so that a run at the robot's own step writes what it did.
  if (c.dt_s > 0.0) j["dt_s"] = c.dt_s;
  if (c.early_end_bar_m > 0.0) {
    j["early_end_bar_m"] = c.early_end_bar_m;
    j["early_end_speed_m_per_s"] = c.early_end_speed_m_per_s;
  }
  if (!c.randomization.empty()) {
    j["randomization"] = {
        {"set", nlohmann::json::parse(c.randomization)}, {"k", c.randomize_k}, {"score", to_string(c.randomize_score)}};
  }
  return j;
}

EvolveConfig config_from_json(const nlohmann::json& j) {
  try {
    EvolveConfig c;
    c.method = parse_fitness_method(j.at("method").get<std::string>());
    c.population = json_integer<int>(j, "population");
    c.teams = json_integer<int>(j, "teams");
    c.replace = json_integer<int>(j, "replace");
    // Checkpoints from before the author's operator existed mutated every value.
    c.mutation = parse_mutation(j.value("mutation", std::string("gaussian")));
    c.sigma_m = j.at("sigma_m").get<double>();
    // Checkpoints from before annealing existed mutated with sigma_m throughout.
    c.sigma_final_m = j.value("sigma_final_m", c.sigma_m);
    c.anneal_episodes = json_integer_or<std::int64_t>(j, "anneal_episodes", 0);
    c.anneal_start_episodes = json_integer_or<std::int64_t>(j, "anneal_start_episodes", 0);
    c.seed = json_integer<std::uint64_t>(j, "seed");
    c.episodes = json_integer<std::int64_t>(j, "episodes");
    c.cables = json_integer<int>(j, "cables");
    c.complexity = json_integer<int>(j, "complexity");
    c.min_rest_length_m = j.at("min_rest_length_m").get<double>();
    c.max_rest_length_m = j.at("max_rest_length_m").get<double>();
    c.period_s = j.at("period_s").get<double>();
    c.duration_s = j.at("duration_s").get<double>();
    c.dt_s = j.value("dt_s", 0.0);
    c.early_end_bar_m = j.value("early_end_bar_m", 0.0);
    c.early_end_speed_m_per_s = j.value("early_end_speed_m_per_s", 0.0);
    c.robot_name = j.at("robot_name").get<std::string>();
    c.robot_hash = j.at("robot_hash").get<std::string>();
    if (j.contains("randomization")) {
      const nlohmann::json& r = j.at("randomization");
      c.randomization = r.at("set").dump();
      c.randomize_k = json_integer<int>(r, "k");
      c.randomize_score = parse_sample_score(r.at("score").get<std::string>());
    }
    return c;
  } catch (const nlohmann::json::exception& e) {
    throw ConfigError(std::string("evolve config: ") + e.what());
  }
}

std::vector<std::string> config_differences(const EvolveConfig& a, const EvolveConfig& b) {
  const nlohmann::json ja = config_to_json(a);
  const nlohmann::json jb = config_to_json(b);
  std::vector<std::string> out;
  auto field = [](const nlohmann::json& j, const std::string& key) { return j.contains(key) ? j.at(key) : nullptr; };
  nlohmann::json keys = ja;
  keys.update(jb);
  for (const auto& [key, value] : keys.items()) {
    if (field(ja, key) != field(jb, key))
      out.push_back(key + ": " + field(ja, key).dump() + " -> " + field(jb, key).dump());
  }
  return out;
}

}  // namespace tensegrity::sim::evolve
