/** @file JsonFileTest.cpp
 *  @brief JSON files: syntax errors name file:line:column without the library's raw text; integers are checked
 *         before conversion (1e300 where an int is expected is an error, never undefined behaviour).
 */
#include "uwb/io/JsonFile.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "IoTestHelpers.h"
#include "uwb/core/Error.h"

namespace uwb {
namespace {

using test::TempDir;
using ::testing::HasSubstr;
using ::testing::Not;

TEST(JsonFile, SyntaxErrorNamesFileLineAndColumn) {
  TempDir dir;
  const std::string path = dir.write("cfg.json", "{\n  \"a\": 1,\n  \"b\": tru\n}\n");
  const std::optional<InputError> e = test::caught<InputError>([&] { (void)readJsonFile(path, "config file"); });
  ASSERT_TRUE(e);
  EXPECT_THAT(e->what(), HasSubstr("cfg.json:3:"));
  EXPECT_THAT(e->what(), HasSubstr("invalid JSON in config file"));
  EXPECT_THAT(e->what(), Not(HasSubstr("json.exception")));
  EXPECT_EQ(e->where().line, 3u);
}

TEST(JsonFile, ANumberBeyondDoubleIsAnInputErrorWithoutLibraryText) {
  TempDir dir;
  const std::string path = dir.write("big.json", R"({"version": 1e400})");
  const std::string message = test::messageOf<InputError>([&] { (void)readJsonFile(path, "bias model"); });
  EXPECT_THAT(message, HasSubstr("big.json"));
  EXPECT_THAT(message, HasSubstr("1e400"));
  EXPECT_THAT(message, Not(HasSubstr("json.exception")));
}

TEST(JsonFile, ADirectoryIsAFileError) {
  TempDir dir;
  EXPECT_THROW((void)readJsonFile(dir.file(""), "config file"), FileError);
}

TEST(JsonFile, IntegersAreCheckedBeforeConversion) {
  using nlohmann::json;
  EXPECT_EQ(jsonInt(json(3), "k", 0, 10), 3);
  EXPECT_EQ(jsonInt(json(3.0), "k", 0, 10), 3);
  EXPECT_EQ(jsonInt(json(-1), "k", -1, 10), -1);
  for (const json& bad : {json(1e300), json(-1e300), json(2.5), json(11), json(-2), json("3"), json(nullptr),
                          json(std::uint64_t{18446744073709551615ull}), json(std::numeric_limits<double>::infinity())}) {
    try {
      (void)jsonInt(bad, "robust_iterations", -1, 10);
      ADD_FAILURE() << "accepted " << bad.dump();
    } catch (const std::invalid_argument& e) {
      EXPECT_THAT(e.what(), HasSubstr("'robust_iterations' must be an integer in [-1, 10]"));
    }
  }
}

TEST(JsonFile, DoublesMustBeFiniteNumbers) {
  using nlohmann::json;
  EXPECT_EQ(jsonDouble(json(0.5), "k"), 0.5);
  EXPECT_THROW((void)jsonDouble(json("0.5"), "k"), std::invalid_argument);
  EXPECT_THROW((void)jsonDouble(json(std::numeric_limits<double>::infinity()), "k"), std::invalid_argument);
  EXPECT_THROW((void)jsonDouble(json(std::nan("")), "k"), std::invalid_argument);
  EXPECT_THROW((void)jsonBool(json(1), "k"), std::invalid_argument);
  EXPECT_THROW((void)jsonString(json(1), "k"), std::invalid_argument);
  EXPECT_THROW((void)jsonMember(json::object(), "models[0]", "id_a"), std::invalid_argument);
}

}  // namespace
}  // namespace uwb
