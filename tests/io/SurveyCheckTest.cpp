/** @file SurveyCheckTest.cpp
 *  @brief The Crazyflie client's anchor-position YAML as a survey, and the survey checks (io/SurveyCheck.h): each
 *         warning fires on the layout it describes, with its numbers, and stays silent on a good layout.
 */
#include "uwb/io/SurveyCheck.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "uwb/core/Error.h"

namespace uwb {
namespace {

using ::testing::HasSubstr;

AnchorSurvey box(double height_top = 2.5) {  // 8 anchors at the corners of a 4 × 4 m room, floor and ceiling
  AnchorSurvey s;
  s.source = "box.yaml";
  int id = 0;
  for (double z : {0.1, height_top})
    for (double x : {0.0, 4.0})
      for (double y : {0.0, 4.0}) s.anchors.push_back({id++, Vec3(x, y, z), Quat::Identity()});
  return s;
}

std::string messages(const std::vector<InputIssue>& issues) {
  std::string out;
  for (const InputIssue& i : issues) out += i.text() + "\n";
  return out;
}

TEST(CfclientAnchors, BlockAndFlowStylesAsPyYamlWritesThem) {
  // GIVEN the file cfclient saves with a current PyYAML (block style) and with an old one (flow style)
  const std::string block = "0:\n  x: 0.0\n  y: -1.5\n  z: 0.15\n1:\n  x: 4\n  y: 2.0e-1\n  z: 2.5\n";
  const std::string flow = "# anchors\n0: {x: 0.0, y: -1.5, z: 0.15}\n1: {x: 4, y: 2.0e-1, z: 2.5}\n";
  for (const std::string& text : {block, flow}) {
    // WHEN read
    const AnchorSurvey s = parseCfclientAnchors(text, "a.yaml");
    // THEN two anchors with their positions, sorted by id
    ASSERT_EQ(s.anchors.size(), 2u) << text;
    EXPECT_EQ(s.anchors[0].id, 0);
    EXPECT_EQ(s.anchors[0].w_p, Vec3(0.0, -1.5, 0.15));
    EXPECT_EQ(s.anchors[1].w_p, Vec3(4.0, 0.2, 2.5));
    EXPECT_EQ(s.source, "a.yaml");
  }
  // AND what formatCfclientAnchors writes reads back exactly
  const AnchorSurvey b = box();
  const AnchorSurvey back = parseCfclientAnchors(formatCfclientAnchors(b), "b.yaml");
  ASSERT_EQ(back.anchors.size(), b.anchors.size());
  for (std::size_t i = 0; i < b.anchors.size(); ++i) EXPECT_EQ(back.anchors[i].w_p, b.anchors[i].w_p);
}

TEST(CfclientAnchors, BadFilesNameTheLineAndWhat) {
  const auto error = [](const std::string& text) {
    try {
      (void)parseCfclientAnchors(text, "a.yaml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_THAT(error(""), HasSubstr("no anchor"));
  EXPECT_THAT(error("0: {x: 1, y: 2, z: 3}\nfoo: {x: 1, y: 2, z: 3}\n"), HasSubstr("a.yaml:2"));
  EXPECT_THAT(error("0: {x: 1, y: 2, z: 3}\nfoo: {x: 1, y: 2, z: 3}\n"), HasSubstr("anchor id must be an integer"));
  EXPECT_THAT(error("300: {x: 1, y: 2, z: 3}\n"), HasSubstr("[0, 255]"));
  EXPECT_THAT(error("0: {x: 1, y: 2, z: 3}\n0: {x: 1, y: 2, z: 3}\n"), HasSubstr("duplicate anchor id 0: already given on line 1"));
  EXPECT_THAT(error("0:\n  x: 1\n  y: 2\n1: {x: 1, y: 2, z: 3}\n"), HasSubstr("a.yaml:1"));
  EXPECT_THAT(error("0:\n  x: 1\n  y: 2\n1: {x: 1, y: 2, z: 3}\n"), HasSubstr("no 'z' coordinate"));
  EXPECT_THAT(error("0:\n  x: 1\n  y: abc\n  z: 1\n"), HasSubstr("a.yaml:3:3 (anchor 0): y must be a finite number"));
  EXPECT_THAT(error("0: {x: 1, y: 2, z: .nan}\n"), HasSubstr("finite"));
  EXPECT_THAT(error("0: {x: 1, y: 2, z: 3, w: 4}\n"), HasSubstr("unknown key 'w'"));
  EXPECT_THAT(error("  x: 1\n"), HasSubstr("before any anchor id"));
}

TEST(SurveyCheck, AGoodLayoutHasNoWarning) {
  const AnchorSurvey s = box();
  EXPECT_TRUE(checkAnchorSeparation(s).empty());
  EXPECT_TRUE(checkAnchorPlane(s).empty());
  const std::vector<Vec3> inside{Vec3(1, 1, 1), Vec3(3, 3, 2), Vec3(2, 2, 0.1)};
  EXPECT_TRUE(checkFlightInsideAnchors(s, inside, "f").empty());
}

TEST(SurveyCheck, ColocatedAnchorsAreNamedWithTheirDistance) {
  AnchorSurvey s = box();
  s.anchors[5].w_p = s.anchors[2].w_p + Vec3(0.1, 0.0, 0.05);  // anchor 5 entered near anchor 2
  const std::vector<InputIssue> w = checkAnchorSeparation(s);
  ASSERT_EQ(w.size(), 1u) << messages(w);
  EXPECT_THAT(w[0].message, HasSubstr("anchors 2 and 5 are 0.112 m apart (< 0.3 m)"));
}

TEST(SurveyCheck, AnchorsAllOnTheCeilingLeaveTheVerticalPoorlyObservable) {
  AnchorSurvey s = box();
  for (Anchor& a : s.anchors) a.w_p.z() = 2.5 + 0.02 * ((a.id + a.id / 2) % 2);  // all on the ceiling, ±1 cm
  const std::vector<InputIssue> w = checkAnchorPlane(s);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_THAT(w[0].message, HasSubstr("all 8 anchors lie within 0.01 m of one horizontal plane (z ≈ 2.51 m)"));
  EXPECT_THAT(w[0].message, HasSubstr("vertical (z) is poorly observable"));
  // a vertical plane (all anchors on one wall) names its normal instead
  for (Anchor& a : s.anchors) a.w_p = Vec3(0.0, a.id % 4, 0.3 * a.id);
  const std::vector<InputIssue> wall = checkAnchorPlane(s);
  ASSERT_EQ(wall.size(), 1u);
  EXPECT_THAT(wall[0].message, HasSubstr("normal 1.00,"));
}

TEST(SurveyCheck, AFlightOutsideTheAnchorsIsWarnedWithShareAndExcursion) {
  const AnchorSurvey s = box();
  std::vector<Vec3> flight;
  for (int i = 0; i < 90; ++i) flight.emplace_back(2.0, 2.0, 1.0);
  for (int i = 0; i < 10; ++i) flight.emplace_back(2.0, 4.0 + 0.08 * (i + 1), 1.0);  // up to 0.8 m beyond y = 4
  const std::vector<InputIssue> w = checkFlightInsideAnchors(s, flight, "traj.csv");
  ASSERT_EQ(w.size(), 1u);
  // 7 of the 10 positions beyond the anchors lie more than 0.25 m outside
  EXPECT_THAT(w[0].text(), HasSubstr("traj.csv: 7.0 % of the flight's 100 positions lie outside the anchors' box"));
  EXPECT_THAT(w[0].message, HasSubstr("up to 0.80 m along y"));
}

TEST(SurveyCheck, AnAnchorIdOfTheFlightMissingFromTheSurveyIsCounted) {
  const AnchorSurvey s = box();
  Flight f;
  f.source = "flight.csv";
  for (int i = 0; i < 30; ++i) f.tdoa.push_back({0.01 * i, i % 3 == 0 ? 9 : 1, 2, 0.5});
  const std::vector<InputIssue> w = checkFlightAnchorIds(s, f);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_THAT(w[0].message, HasSubstr("anchor 9 is in 10 of the flight's 30 TDoA"));
}

}  // namespace
}  // namespace uwb
