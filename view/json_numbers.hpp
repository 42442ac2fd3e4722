// SPDX-License-Identifier: Apache-2.0
#pragma once
// Compact JSON for large number arrays: a fixed format per array instead of the
// 17 significant digits a general JSON writer gives every float, which would make
// a replay five times larger and slower to open.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace tensegrity::view {

std::string json_string(const std::string& text);

// Appends `,"name":[v0,v1,...]` with each value printed by `format` (printf).
template <typename T>
void append_array(std::string& out, const char* name, const std::vector<T>& values, const char* format) {
  out += ",\"";
  out += name;
  out += "\":[";
  char buf[48];
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i > 0) out += ',';
    if (!std::isfinite(static_cast<double>(values[i]))) {  // a model that blew up: JSON has no NaN
      out += "null";
      continue;
    }
    const int len = std::snprintf(buf, sizeof buf, format, static_cast<double>(values[i]));
    out.append(buf, static_cast<std::size_t>(len));
  }
  out += ']';
}

}  // namespace tensegrity::view
