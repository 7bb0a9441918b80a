/** @file TdoaResidualsTest.cpp
 *  @brief TDoA residuals against ground truth: zero for noise-free data, the sign convention, the lever arm.
 */
#include "uwb/sim/TdoaResiduals.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "io/IoTestHelpers.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {
namespace {

TEST(TdoaResiduals, NoiseFreeMeasurementsHaveZeroResidualWithTheLeverArmInTheBodyFrame) {
  // GIVEN a flight whose TDoA is generated from the ground truth with the UTIL lever arm, rolled 20°
  const AnchorSurvey survey = test::cornerSurvey();
  Flight f;
  f.pose = test::circle(200.0, 2.0);
  for (auto& p : f.pose) p.w_q_b = p.w_q_b * test::roll(0.35);
  f.pose_has_orientation = true;
  for (int i = 0; i < 300; ++i) {
    const double t = 0.0033 * i + 0.001;
    const int a = i % 8;
    const int b = (i + 1) % 8;
    const PoseSample gt = *PoseTrack(f).interpolate(t);
    f.tdoa.push_back({t, a, b, predictTdoa(gt.w_p_b, gt.w_q_b, kUtilTagOffset_b, survey.position(a), survey.position(b))});
  }
  // WHEN residuals are computed
  TdoaResidualReport report;
  const auto r = tdoaResiduals(f, survey, PoseTrack(f), {}, &report);
  // THEN they vanish and everything is airborne
  ASSERT_EQ(r.size(), 300u);
  EXPECT_EQ(report.n_residuals, 300u);
  EXPECT_EQ(report.n_no_ground_truth, 0u);
  for (const auto& x : r) {
    EXPECT_NEAR(x.residual_m, 0.0, 1e-12);
    EXPECT_TRUE(x.airborne);
    EXPECT_DOUBLE_EQ(x.measured_m - x.predicted_m, x.residual_m);
  }
  EXPECT_EQ(r[5].index, 5u);
}

TEST(TdoaResiduals, SignConventionIsRangeToBMinusRangeToA) {
  // GIVEN a tag at the origin (no lever arm), anchor A at 1 m and anchor B at 3 m, measurement 2.5 m
  AnchorSurvey survey;
  survey.anchors = {{0, Vec3(1, 0, 0), Quat::Identity()}, {1, Vec3(0, 3, 0), Quat::Identity()}};
  Flight f;
  f.pose = {{0.0, Vec3::Zero(), Quat::Identity()}, {0.01, Vec3::Zero(), Quat::Identity()}};
  f.pose_has_orientation = true;
  f.tdoa = {{0.005, 0, 1, 2.5}};
  TdoaResidualParams params;
  params.b_t_tag = Vec3::Zero();
  const auto r = tdoaResiduals(f, survey, PoseTrack(f), params);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_NEAR(r[0].predicted_m, 2.0, 1e-12);  // |p − a_B| − |p − a_A| = 3 − 1
  EXPECT_NEAR(r[0].residual_m, 0.5, 1e-12);
  EXPECT_FALSE(r[0].airborne) << "z = 0";
}

TEST(TdoaResiduals, PositionOnlyTrackAddsTheLeverArmInTheWorldFrame) {
  const AnchorSurvey survey = test::cornerSurvey();
  Flight f;
  f.pose = {{0.0, Vec3(0.5, 0.2, 1.0), Quat::Identity()}, {0.01, Vec3(0.5, 0.2, 1.0), Quat::Identity()}};
  f.pose_has_orientation = false;
  const Vec3 w_p_tag = Vec3(0.5, 0.2, 1.0) + kUtilTagOffset_b;
  const double h = (w_p_tag - survey.position(3)).norm() - (w_p_tag - survey.position(2)).norm();
  f.tdoa = {{0.004, 2, 3, h + 0.1}};
  const auto r = tdoaResiduals(f, survey, PoseTrack(f));
  ASSERT_EQ(r.size(), 1u);
  EXPECT_NEAR(r[0].residual_m, 0.1, 1e-12);
}

TEST(TdoaResiduals, MeasurementsWithoutTruthOrAnchorAreCountedNotDropped) {
  const AnchorSurvey survey = test::cornerSurvey();
  Flight f;
  f.pose = test::circle(200.0, 1.0);
  f.pose_has_orientation = true;
  f.tdoa = {{-0.5, 0, 1, 0.0}, {0.5, 0, 1, 0.0}, {0.6, 0, 9, 0.0}, {2.0, 1, 2, 0.0}};
  TdoaResidualReport report;
  const auto r = tdoaResiduals(f, survey, PoseTrack(f), {}, &report);
  EXPECT_EQ(r.size(), 1u);
  EXPECT_EQ(report.n_measurements, 4u);
  EXPECT_EQ(report.n_no_ground_truth, 2u);
  EXPECT_EQ(report.n_unknown_anchor, 1u);
  EXPECT_EQ(report.n_residuals + report.n_no_ground_truth + report.n_unknown_anchor, report.n_measurements);
}

}  // namespace
}  // namespace uwb
