// SPDX-License-Identifier: Apache-2.0
#pragma once
// Integer fields of JSON from outside (checkpoints, MPI setups). nlohmann's get<int>()
// converts a float or an integer of another range without a check, and converting a
// double beyond int's range is undefined behaviour; every integer field of such a file
// is read here, and one that is not an integer of the field's range is an error naming it.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "sim/evolve/config.hpp"

namespace tensegrity::sim::evolve {

template <class T>
T json_integer_value(const nlohmann::json& v, const std::string& field) {
  if (v.is_number_unsigned()) {
    const auto u = v.get<std::uint64_t>();
    if (!std::in_range<T>(u)) throw ConfigError(field + ": " + v.dump() + " is out of range");
    return static_cast<T>(u);
  }
  if (v.is_number_integer()) {
    const auto i = v.get<std::int64_t>();
    if (!std::in_range<T>(i)) throw ConfigError(field + ": " + v.dump() + " is out of range");
    return static_cast<T>(i);
  }
  throw ConfigError(field + ": must be an integer, not " + v.dump());
}

// j[key], which must be there; errors name it `field` (default: the key).
template <class T>
T json_integer(const nlohmann::json& j, const std::string& key, const std::string& field = {}) {
  return json_integer_value<T>(j.at(key), field.empty() ? key : field);
}

// j[key], or `fallback` when the file has no such field.
template <class T>
T json_integer_or(const nlohmann::json& j, const std::string& key, T fallback) {
  return j.contains(key) ? json_integer<T>(j, key) : fallback;
}

}  // namespace tensegrity::sim::evolve
