/** @file AnchorSurveyTest.cpp
 *  @brief UTIL anchor survey reader/writer: any ids, exact round trip, errors with line numbers.
 */
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "IoTestHelpers.h"
#include "uwb/core/Error.h"
#include "uwb/io/UtilCsv.h"

namespace uwb {
namespace {

using test::TempDir;
using ::testing::HasSubstr;

void expectSurveyError(const std::string& text, const std::vector<std::string>& parts) {
  TempDir dir;
  const std::string path = dir.write("s.txt", text);
  try {
    (void)readAnchorSurvey(path);
    ADD_FAILURE() << "expected InputError for:\n" << text;
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr(path));
    for (const auto& p : parts) EXPECT_THAT(std::string(e.what()), HasSubstr(p));
  }
}

TEST(AnchorSurvey, ReadsPositionsAndQuaternionsWithAnyIds) {
  // GIVEN a survey with non-contiguous ids, positions first then quaternions, in any order
  TempDir dir;
  const std::string path = dir.write("s.txt",
                                     "an12_p,1.5,-2,0.25\n"
                                     "an3_p,-3.036782195455842,-4.036436287676323,0.2077594372949114\n"
                                     "\n"
                                     "an3_quat,0.6558824744028585,0.2510190065156526,0.6634491515819576,"
                                     "-0.2581527869387805\r\n"
                                     "an12_quat,0,0,0,1\n");
  // WHEN it is read
  const AnchorSurvey s = readAnchorSurvey(path);
  // THEN anchors are sorted by id with full-precision values
  ASSERT_EQ(s.anchors.size(), 2u);
  EXPECT_EQ(s.anchors[0].id, 3);
  EXPECT_EQ(s.anchors[1].id, 12);
  EXPECT_EQ(s.position(3).x(), -3.036782195455842);
  EXPECT_EQ(s.at(3).w_q.w(), -0.2581527869387805);
  EXPECT_EQ(s.position(12), Vec3(1.5, -2, 0.25));
  EXPECT_TRUE(s.contains(12));
  EXPECT_FALSE(s.contains(0));
  EXPECT_THROW((void)s.at(0), std::out_of_range);
  EXPECT_EQ(s.source, path);
}

TEST(AnchorSurvey, MissingQuaternionDefaultsToIdentity) {
  TempDir dir;
  const AnchorSurvey s = readAnchorSurvey(dir.write("s.txt", "an0_p,1,2,3\n"));
  EXPECT_TRUE(s.at(0).w_q.isApprox(Quat::Identity()));
}

TEST(AnchorSurvey, RoundTripIsExact) {
  // GIVEN a survey with awkward values
  AnchorSurvey s;
  s.anchors.push_back({7, Vec3(0.1 + 0.2, -1e-17, 3.0), Quat(0.3, 0.1, -0.2, 0.9).normalized()});
  s.anchors.push_back({0, Vec3(-3.1619237009372023, 3.348979043127884, 0.17948550711049793), Quat::Identity()});
  s.anchors.push_back({100, Vec3(1, 2, 3), Quat(0, 1, 0, 0)});
  // WHEN written and read back
  TempDir dir;
  writeAnchorSurvey(s, dir.file("s.txt"));
  const AnchorSurvey back = readAnchorSurvey(dir.file("s.txt"));
  // THEN identical, sorted by id
  ASSERT_EQ(back.anchors.size(), 3u);
  EXPECT_EQ(back.anchors[0].id, 0);
  EXPECT_EQ(back.anchors[1].id, 7);
  EXPECT_EQ(back.anchors[2].id, 100);
  for (const Anchor& a : s.anchors) {
    EXPECT_TRUE(test::sameBits(back.at(a.id).w_p, a.w_p)) << a.id;
    EXPECT_TRUE(test::sameBits(back.at(a.id).w_q, a.w_q)) << a.id;
  }
}

TEST(AnchorSurveyMalformed, DuplicateId) {
  expectSurveyError("an0_p,1,2,3\nan1_p,1,2,3\nan0_p,4,5,6\n", {":3:1", "duplicate anchor id 0", "line 1"});
}

TEST(AnchorSurveyMalformed, DuplicateQuaternion) {
  expectSurveyError("an0_p,1,2,3\nan0_quat,0,0,0,1\nan0_quat,0,0,0,1\n", {":3:1", "duplicate anchor id 0"});
}

TEST(AnchorSurveyMalformed, QuaternionWithoutPosition) {
  expectSurveyError("an0_p,1,2,3\nan5_quat,0,0,0,1\n", {":2:1", "missing position", "an5_p"});
}

TEST(AnchorSurveyMalformed, MalformedLabel) {
  expectSurveyError("an0_p,1,2,3\nanchor1,1,2,3\n", {":2:1", "malformed survey line"});
  expectSurveyError("anX_p,1,2,3\n", {":1:1", "malformed anchor id"});
  expectSurveyError("an2147483647_p,1,2,3\n", {":1:1", "malformed anchor id", "[0, 255]"});
  expectSurveyError("an256_p,1,2,3\n", {":1:1", "[0, 255]"});
  expectSurveyError("an-1_p,1,2,3\n", {":1:1", "malformed anchor id"});
  expectSurveyError("an1_pos,1,2,3\n", {":1:1", "unknown kind 'pos'"});
}

TEST(AnchorSurveyMalformed, WrongNumberOfValues) {
  expectSurveyError("an0_p,1,2\n", {":1:", "needs 3 numbers, found 2"});
  expectSurveyError("an0_p,1,2,3\nan0_quat,0,0,1\n", {":2:", "needs 4 numbers, found 3"});
}

TEST(AnchorSurveyMalformed, NonNumericAndNaN) {
  expectSurveyError("an0_p,1,two,3\n", {":1:3 (an0_p)", "not a number: 'two'"});
  expectSurveyError("an0_p,1,nan,3\n", {":1:3 (an0_p)", "NaN or Inf"});
}

TEST(AnchorSurveyMalformed, EmptySurvey) { expectSurveyError("\n\n", {"no anchors"}); }

TEST(AnchorSurveyMalformed, MissingFileIsAFileError) {
  TempDir dir;
  EXPECT_THROW((void)readAnchorSurvey(dir.file("none.txt")), FileError);
}

TEST(RealDataAnchorSurvey, AllShippedSurveysReadWithEightAnchors) {
  const auto real = test::realDir();
  const std::vector<std::filesystem::path> files = {
      real / "util-pilot/survey/anchor_0425_survey.txt", real / "util-pilot/survey/anchor_0426_survey.txt",
      real / "util-final-extract/survey/anchor_const1_survey.txt",
      real / "util-final-extract/survey/anchor_const4_survey.txt"};
  if (!std::filesystem::exists(files[0])) GTEST_SKIP() << "real data not found under " << real;
  for (const auto& f : files) {
    SCOPED_TRACE(f.string());
    const AnchorSurvey s = readAnchorSurvey(f.string());
    ASSERT_EQ(s.anchors.size(), 8u);
    for (int id = 0; id < 8; ++id) EXPECT_TRUE(s.contains(id));
    EXPECT_NEAR(s.at(0).w_q.norm(), 1.0, 1e-6);
  }
}

}  // namespace
}  // namespace uwb
