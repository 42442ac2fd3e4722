// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: an end cap's config file (firmware/app/config.hpp), as `endcap
// --config FILE` reads it.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "firmware/app/config.hpp"
#include "firmware/app/control_loop.hpp"

namespace app = tensegrity::fw::app;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const app::EndcapAppConfig config = app::parse_config(text, 3, "fuzz");
    (void)app::make_loop_settings(config);  // the settings the loop derives from it
  } catch (const app::ConfigError&) {
  }
  return 0;
}
