// SPDX-License-Identifier: Apache-2.0
#pragma once
// The page (view/web/), compiled into the program at build time
// (embed_assets.cmake): `tensegrity view` needs no install step and no files
// beside the binary, from the build tree as from a package.
#include <cstddef>
#include <string_view>

namespace tensegrity::view {

struct Asset {
  std::string_view path;  // URL path, e.g. "/js/main.js"
  std::string_view content_type;
  std::string_view body;
};

// The asset served at `path`, or nullptr.
const Asset* find_asset(std::string_view path);

}  // namespace tensegrity::view
