// SPDX-License-Identifier: Apache-2.0
#pragma once
// An episode's result as JSON, beside its type: the object `tensegrity sim --json`
// prints and `analyze --json` nests as "episode" (docs/reference/files.md).
#include <nlohmann/json.hpp>

#include "sim/model/episode.hpp"

namespace tensegrity::sim {

nlohmann::json episode_json(const EpisodeResult& result);

}  // namespace tensegrity::sim
