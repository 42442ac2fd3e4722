// SPDX-License-Identifier: Apache-2.0
// JsonReader::choice: a field that takes one of a few words.
#include "format/json_reader.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace tensegrity::format {
namespace {

using ::testing::HasSubstr;
using Reader = JsonReader<std::runtime_error>;

std::string error_of(const nlohmann::json& doc, std::size_t fallback = 0) {
  try {
    Reader(doc, "file.json", "start").choice("pose", {"a", "b", "c"}, fallback);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(JsonReaderChoice, ReturnsTheIndexOrTheFallbackWhenAbsent) {
  const nlohmann::json doc = {{"pose", "c"}};  // the reader keeps a reference
  const Reader r(doc, "file.json", "start");
  EXPECT_EQ(r.choice("pose", {"a", "b", "c"}, 0), 2U);
  EXPECT_EQ(r.choice("other", {"a", "b"}, 1), 1U);
}

TEST(JsonReaderChoice, RefusesAnythingElseNamingTheFieldAndTheOptions) {
  EXPECT_EQ(error_of({{"pose", "d"}}), "file.json: start.pose: must be \"a\", \"b\" or \"c\" (got \"d\")");
  EXPECT_EQ(error_of({{"pose", ""}}), "file.json: start.pose: must be \"a\", \"b\" or \"c\" (got \"\")");
  EXPECT_THAT(error_of({{"pose", 3}}), HasSubstr("start.pose: must be a string"));
  EXPECT_THAT(error_of({{"pose", "A"}}), HasSubstr("(got \"A\")")) << "case matters";
}

}  // namespace
}  // namespace tensegrity::format
