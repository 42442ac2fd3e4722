// SPDX-License-Identifier: Apache-2.0
// Reading one JSON object of a file the project's processes exchange (the end cap's
// config and stats, robot descriptions) with errors that name the file and the
// field's path ("endcap.json: timeouts.drive_heartbeat_s: must be > 0",
// "superball.json: cables[3].nodes[1]: node 12 does not exist"), and without
// nlohmann's silent conversions (-1 read as a count, 2.5 as an integer). `Error` is
// the exception the caller's users catch (ConfigError, StatsError, RobotError).
#pragma once

#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

namespace tensegrity::format {

// Parses `text`, or throws Error("source: not valid JSON: ...").
template <typename Error>
nlohmann::json parse_json(const std::string& text, const std::string& source) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw Error(source + ": not valid JSON: " + e.what());
  }
}

template <typename Error>
class JsonReader {
 public:
  using json = nlohmann::json;

  JsonReader(const json& j, std::string source, std::string path)
      : j_(j), source_(std::move(source)), path_(std::move(path)) {
    if (!j_.is_object()) fail("", "must be an object");
  }

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw Error(source_ + ": " + field(key) + ": " + what);
  }
  std::string field(const std::string& key) const {
    if (path_.empty()) return key.empty() ? "(top level)" : key;
    return key.empty() ? path_ : path_ + "." + key;
  }
  // Any other key is an error (a misspelt field must not pass as a default).
  void only(std::initializer_list<const char*> keys) const {
    for (const auto& [k, v] : j_.items()) {
      bool known = false;
      for (const char* allowed : keys) known = known || k == allowed;
      if (!known) fail(k, "unknown field");
    }
  }
  bool has(const char* key) const { return j_.contains(key); }
  bool null_or_absent(const char* key) const { return !has(key) || j_.at(key).is_null(); }
  const json& at(const char* key) const {
    if (!has(key)) fail(key, "missing");
    return j_.at(key);
  }
  JsonReader object(const char* key) const { return JsonReader(at(key), source_, field(key)); }
  // An optional object: when absent, an empty one (its fields take their defaults).
  JsonReader object_or_empty(const char* key) const {
    static const json kEmpty = json::object();
    return has(key) ? object(key) : JsonReader(kEmpty, source_, field(key));
  }

  double number(const char* key, double fallback, bool required = false) const {
    if (!has(key)) {
      if (required) fail(key, "missing");
      return fallback;
    }
    const json& v = j_.at(key);
    if (!v.is_number()) fail(key, "must be a number");
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(key, "must be finite");
    return x;
  }
  double number(const char* key) const { return number(key, 0.0, true); }
  double positive(const char* key, double fallback, bool required = false) const {
    const double x = number(key, fallback, required);
    if (!(x > 0.0)) fail(key, "must be > 0");
    return x;
  }
  std::uint64_t count(const char* key) const {
    const json& v = at(key);
    if (!v.is_number_unsigned()) fail(key, "must be a count (an integer >= 0)");
    return v.get<std::uint64_t>();
  }
  std::int64_t integer(const char* key) const {
    const json& v = at(key);
    if (!v.is_number_integer()) fail(key, "must be an integer");
    return v.get<std::int64_t>();
  }
  // Non-empty unless `allow_empty`.
  std::string string(const char* key, bool allow_empty = false) const {
    const json& v = at(key);
    if (!v.is_string() || (!allow_empty && v.get<std::string>().empty())) {
      fail(key, allow_empty ? "must be a string" : "must be a non-empty string");
    }
    return v.get<std::string>();
  }
  // One of `options` (absent: `fallback`), as its index; anything else is refused
  // with the options spelt out.
  std::size_t choice(const char* key, std::initializer_list<const char*> options, std::size_t fallback) const {
    if (!has(key)) return fallback;
    const std::string got = string(key, true);
    std::size_t i = 0;
    std::string listed;
    for (const char* option : options) {
      if (got == option) return i;
      listed += (i == 0 ? "" : (i + 1 == options.size() ? " or " : ", ")) + ("\"" + std::string(option) + "\"");
      ++i;
    }
    fail(key, "must be " + listed + " (got \"" + got + "\")");
  }
  bool boolean(const char* key, bool fallback) const {
    if (!has(key)) return fallback;
    if (!j_.at(key).is_boolean()) fail(key, "must be true or false");
    return j_.at(key).get<bool>();
  }
  bool boolean(const char* key) const {
    at(key);
    return boolean(key, false);
  }
  double non_negative(const char* key, double fallback, bool required = false) const {
    const double x = number(key, fallback, required);
    if (x < 0.0) fail(key, "must be >= 0");
    return x;
  }
  double non_negative(const char* key) const { return non_negative(key, 0.0, true); }

  // Arrays: the array itself, and paths and values of its elements, which need not
  // be objects ("nodes_m[3][1]").
  const json& array(const char* key) const {
    const json& v = at(key);
    if (!v.is_array()) fail(key, "must be an array");
    return v;
  }
  // An element that is an object, read with its own path ("cables[4]").
  JsonReader element(const char* key, std::size_t i) const {
    return JsonReader(array(key).at(i), source_, field(key) + "[" + std::to_string(i) + "]");
  }
  // `path` as field() makes it, with any [i] appended.
  [[noreturn]] void fail_at(const std::string& path, const std::string& what) const {
    throw Error(source_ + ": " + path + ": " + what);
  }
  double number_at(const json& v, const std::string& path) const {
    if (!v.is_number()) fail_at(path, "must be a number");
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail_at(path, "must be finite");
    return x;
  }

 private:
  const json& j_;
  std::string source_;
  std::string path_;
};

}  // namespace tensegrity::format
