// SPDX-License-Identifier: Apache-2.0
#include "view/json_numbers.hpp"

#include <nlohmann/json.hpp>

namespace tensegrity::view {

std::string json_string(const std::string& text) { return nlohmann::json(text).dump(); }

}  // namespace tensegrity::view
