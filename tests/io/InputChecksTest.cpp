/** @file InputChecksTest.cpp
 *  @brief Plausibility checks: survey geometry (one point, one line, coplanar) and stream rates (millisecond
 *         stamps), each naming the file and the field.
 */
#include "uwb/io/InputChecks.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "uwb/core/Error.h"

namespace uwb {
namespace {

using ::testing::HasSubstr;

AnchorSurvey survey(const std::vector<Vec3>& positions) {
  AnchorSurvey s;
  s.source = "survey.txt";
  for (std::size_t i = 0; i < positions.size(); ++i) s.anchors.push_back({static_cast<int>(i), positions[i], Quat::Identity()});
  return s;
}

/// An 8-anchor box like the UTIL arenas (≈ 7 m × 8 m × 3 m).
AnchorSurvey boxSurvey() {
  std::vector<Vec3> p;
  for (double x : {-3.0, 4.0})
    for (double y : {-4.0, 4.0})
      for (double z : {0.2, 3.0}) p.emplace_back(x, y, z);
  return survey(p);
}

std::size_t count(const std::vector<InputIssue>& issues, IssueSeverity s) {
  return static_cast<std::size_t>(
      std::count_if(issues.begin(), issues.end(), [s](const InputIssue& i) { return i.severity == s; }));
}

TEST(SurveyGeometry, ABoxOfAnchorsPasses) { EXPECT_TRUE(checkSurveyGeometry(boxSurvey()).empty()); }

TEST(SurveyGeometry, AllAnchorsAtOnePointIsAnError) {
  const auto issues = checkSurveyGeometry(survey(std::vector<Vec3>(8, Vec3(1, 2, 3))));
  ASSERT_EQ(count(issues, IssueSeverity::kError), 1u);
  EXPECT_THAT(issues[0].text(), HasSubstr("survey.txt"));
  EXPECT_THAT(issues[0].message, HasSubstr("one point"));
  EXPECT_THROW(throwOnError(issues), InputError);
}

TEST(SurveyGeometry, AnchorsOnOneLineAreAnError) {
  const auto issues = checkSurveyGeometry(survey({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {4, 0.01, 0}}));
  ASSERT_EQ(count(issues, IssueSeverity::kError), 1u);
  EXPECT_THAT(issues[0].message, HasSubstr("one line"));
}

TEST(SurveyGeometry, CoplanarAnchorsAndTooFewAnchorsAreWarnings) {
  const auto flat = checkSurveyGeometry(survey({{0, 0, 2}, {5, 0, 2}, {0, 5, 2}, {5, 5, 2}, {2, 2, 2.05}}));
  ASSERT_EQ(flat.size(), 1u);
  EXPECT_EQ(flat[0].severity, IssueSeverity::kWarning);
  EXPECT_THAT(flat[0].message, HasSubstr("coplanar"));
  EXPECT_NO_THROW(throwOnError(flat));
  const auto three = checkSurveyGeometry(survey({{0, 0, 0}, {5, 0, 1}, {0, 5, 2}}));
  ASSERT_EQ(three.size(), 1u);
  EXPECT_THAT(three[0].message, HasSubstr("at least 4"));
}

TEST(SurveyGeometry, ThePrincipalSpreadsAreThoseOfTheBox) {
  const SurveyGeometry g = surveyGeometry(boxSurvey());
  EXPECT_NEAR(g.principal_std_m(0), 4.0, 1e-12);   // y: ±4
  EXPECT_NEAR(g.principal_std_m(1), 3.5, 1e-12);   // x: ±3.5
  EXPECT_NEAR(g.principal_std_m(2), 1.4, 1e-12);   // z: ±1.4
  EXPECT_TRUE(g.w_min.isApprox(Vec3(-3, -4, 0.2)));
}

/// A flight with TDoA at 400 Hz and IMU at 1 kHz over 2 s; `imu_scale` multiplies the IMU stamps.
Flight flight(double imu_scale) {
  Flight f;
  f.source = "flight.csv";
  for (int i = 0; i < 800; ++i) f.tdoa.push_back({i / 400.0, 0, 1, 0.5});
  for (int i = 0; i < 2000; ++i) {
    f.acc.push_back({imu_scale * i / 1000.0, Vec3(0, 0, 9.81)});
    f.gyro.push_back({imu_scale * i / 1000.0, Vec3::Zero()});
  }
  return f;
}

TEST(StreamRates, PlausibleRatesPass) { EXPECT_TRUE(checkStreamRates(flight(1.0)).empty()); }

TEST(StreamRates, ImuStampsInMillisecondsAreAnErrorNamingTheTimeColumn) {
  // GIVEN IMU stamps written in milliseconds (1 kHz looks like 1 Hz)
  const auto issues = checkStreamRates(flight(1000.0));
  // THEN both IMU streams are flagged as errors, each naming its time column
  ASSERT_EQ(count(issues, IssueSeverity::kError), 2u);
  EXPECT_EQ(issues[0].where.field, "t_acc");
  EXPECT_EQ(issues[1].where.field, "t_gyro");
  EXPECT_THAT(issues[0].text(), HasSubstr("flight.csv (t_acc)"));
  EXPECT_THAT(issues[0].message, HasSubstr("milliseconds"));
}

TEST(StreamRates, AStreamSpanningFarLongerThanTheTdoaIsFlagged) {
  Flight f = flight(1.0);
  // baro at a plausible 1 Hz, but over 200 s while the TDoA stream covers 2 s
  for (int i = 0; i < 200; ++i) f.baro.push_back({i * 1.0, 1000.0});
  const auto issues = checkStreamRates(f);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].severity, IssueSeverity::kWarning);
  EXPECT_EQ(issues[0].where.field, "t_baro");
}

}  // namespace
}  // namespace uwb
