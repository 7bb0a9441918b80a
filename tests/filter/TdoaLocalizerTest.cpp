/** @file TdoaLocalizerTest.cpp
 *  @brief The estimator on synthetic flights: convergence (static, constant velocity, TDoA-only), the χ² gate and
 *         robust weights, and the ground phase / take-off logic (docs/math/filter.md F11–F18).
 */
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include "FilterTestUtil.h"
#include "uwb/filter/OutlierGate.h"
#include "uwb/filter/TdoaLocalizer.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {
namespace {

/// 8 anchors on the corners of a 7 × 8 × 3 m box, alternating low/high (like the UTIL arena).
AnchorTable boxAnchors() {
  AnchorTable t;
  const double z_lo = 0.2, z_hi = 3.0;
  const Vec3 c[8] = {{-3, -4, z_lo}, {-3, 4, z_hi}, {3.5, 4, z_lo}, {4, -4, z_hi},
                     {-3, -4.2, z_hi}, {4, -3.8, z_lo}, {4, 4, z_hi}, {-3, 3.5, z_lo}};
  for (int i = 0; i < 8; ++i) t.set(i, c[i]);
  return t;
}

using filtertest::Truth;

/// Synthetic log over [0, duration_s] (filtertest::flightLog).
SensorLog makeLog(const AnchorTable& anchors, const std::function<Truth(double)>& truth, double duration_s,
                  double sigma_m, bool with_imu, unsigned seed,
                  const std::function<double(double, int)>& tdoa_offset = {}) {
  return filtertest::flightLog(anchors, truth, 0.0, duration_s, sigma_m, with_imu, seed, tdoa_offset);
}

double finalError(const LocalizerResult& r, const std::function<Truth(double)>& truth) {
  const LocalizerEstimate& e = r.estimates.back();
  return (e.x.w_p_b - truth(e.t_s).p).norm();
}

TEST(TdoaLocalizer, StaticHoverConvergesWithoutGroundTruthStart) {
  // GIVEN a body hovering still and noisy TDoA, no start position, no ground phase
  const AnchorTable anchors = boxAnchors();
  const auto truth = [](double) { return Truth{Vec3(0.5, -0.3, 1.5), Vec3::Zero(), Vec3::Zero()}; };
  EkfParams p;
  p.ground_phase = GroundPhase::kNone;
  // WHEN localizing 10 s
  const LocalizerResult r = TdoaLocalizer(p, anchors).run(makeLog(anchors, truth, 10.0, 0.1, true, 1));
  // THEN it converges close to the truth and uses the measurements
  EXPECT_LT(finalError(r, truth), 0.1);
  EXPECT_GT(r.summary.n_tdoa_used, 3000u);
}

TEST(TdoaLocalizer, ConstantVelocityConverges) {
  // GIVEN a body moving at constant velocity
  const AnchorTable anchors = boxAnchors();
  const Vec3 v(0.3, 0.2, 0.0);
  const auto truth = [&](double t) { return Truth{Vec3(-1.0, -1.0, 1.5) + v * t, v, Vec3::Zero()}; };
  EkfParams p;
  p.ground_phase = GroundPhase::kNone;
  // WHEN localizing 10 s
  const LocalizerResult r = TdoaLocalizer(p, anchors).run(makeLog(anchors, truth, 10.0, 0.1, true, 2));
  // THEN the position and the velocity are tracked (the velocity over the last 4 s: one sample's error is noisy)
  EXPECT_LT(finalError(r, truth), 0.15);
  double v_err2 = 0.0;
  int n = 0;
  for (const LocalizerEstimate& e : r.estimates) {
    if (e.t_s < 6.0) continue;
    v_err2 += (e.x.w_v_b - v).squaredNorm();
    ++n;
  }
  ASSERT_GT(n, 100);
  EXPECT_LT(std::sqrt(v_err2 / n), 0.2);
}

TEST(TdoaLocalizer, TdoaOnlyModeIsSelectedWithoutImuAndConverges) {
  // GIVEN a flight without IMU
  const AnchorTable anchors = boxAnchors();
  const Vec3 v(0.2, -0.1, 0.0);
  const auto truth = [&](double t) { return Truth{Vec3(0.0, 0.5, 1.2) + v * t, v, Vec3::Zero()}; };
  // WHEN localizing with the default (IMU) parameters
  const LocalizerResult r = TdoaLocalizer(EkfParams{}, anchors).run(makeLog(anchors, truth, 8.0, 0.1, false, 3));
  // THEN the constant-velocity model was used and converged
  EXPECT_EQ(r.summary.process_model, ProcessModel::kConstantVelocity);
  EXPECT_LT(finalError(r, truth), 0.15);
}

TEST(OutlierGate, RejectsGrossOutlierAndKeepsState) {
  // GIVEN a converged filter at a known position
  const AnchorTable anchors = boxAnchors();
  Ekf ekf(EkfParams{});
  NavState x;
  x.w_p_b = Vec3(0.2, 0.1, 1.5);
  ErrMat P = initialCovariance(EkfParams{});
  P.block<3, 3>(kPos, kPos) = Mat3::Identity() * 0.01;
  ekf.initialize(x, P);
  const Vec3 p_tag = tagPosition(x.w_p_b, x.w_q_b, kUtilTagOffset_b);
  const double z_true = range(p_tag, anchors.find(1)->m) - range(p_tag, anchors.find(0)->m);
  TdoaUpdateOptions opt;
  opt.sigma_m = 0.2;
  opt.gate_sigma = 4.0;
  // WHEN a measurement 3 m off arrives
  const TdoaUpdateResult bad = updateTdoa(ekf, anchors, {0.0, 0, 1, z_true + 3.0}, opt);
  // THEN it is rejected and the state is untouched
  EXPECT_EQ(bad.outcome, UpdateOutcome::kRejectedOutlier);
  EXPECT_GT(bad.nis, 16.0);
  EXPECT_EQ(ekf.state().w_p_b, x.w_p_b);
  // AND a consistent one is applied with full weight
  const TdoaUpdateResult good = updateTdoa(ekf, anchors, {0.0, 0, 1, z_true + 0.05}, opt);
  EXPECT_EQ(good.outcome, UpdateOutcome::kApplied);
  EXPECT_DOUBLE_EQ(good.weight, 1.0);
  // AND an unknown anchor is reported as such
  EXPECT_EQ(updateTdoa(ekf, anchors, {0.0, 0, 42, 0.0}, opt).outcome, UpdateOutcome::kUnknownAnchor);
}

TEST(OutlierGate, RobustWeightsFollowTheLoss) {
  EXPECT_DOUBLE_EQ(robustWeight(RobustLoss::kNone, 10.0, 1.0), 1.0);
  EXPECT_DOUBLE_EQ(robustWeight(RobustLoss::kHuber, 0.5, 1.0), 1.0);
  EXPECT_DOUBLE_EQ(robustWeight(RobustLoss::kHuber, 4.0, 1.0), 0.25);
  EXPECT_DOUBLE_EQ(robustWeight(RobustLoss::kCauchy, 1.0, 1.0), 0.5);
  // a large innovation relative to the prior gets a weight below one; a small one keeps weight one
  EXPECT_LT(robustUpdateWeight(RobustLoss::kHuber, 1.0, 2.0, 0.01, 0.04, 3), 1.0);
  EXPECT_DOUBLE_EQ(robustUpdateWeight(RobustLoss::kHuber, 1.0, 0.05, 0.01, 0.04, 3), 1.0);
}

TEST(GroundPhase, UserGivenStartSkipsMultilateration) {
  // GIVEN a hovering body and a start position given by the user
  const AnchorTable anchors = boxAnchors();
  const auto truth = [](double) { return Truth{Vec3(-0.5, 0.5, 1.0), Vec3::Zero(), Vec3::Zero()}; };
  EkfParams p;
  p.ground_phase = GroundPhase::kNone;
  p.has_start_position = true;
  p.start_w_p_b = Vec3(-0.5, 0.5, 1.0);
  // WHEN localizing
  const LocalizerResult r = TdoaLocalizer(p, anchors).run(makeLog(anchors, truth, 3.0, 0.1, true, 5));
  // THEN the first estimate is already at the start and the end is accurate
  EXPECT_LT((r.estimates.front().x.w_p_b - p.start_w_p_b).norm(), 0.01);
  EXPECT_LT(finalError(r, truth), 0.1);
}

TEST(EkfParams, ValidateRejectsBadValues) {
  EkfParams p;
  EXPECT_NO_THROW(p.validate());
  p.tdoa_sigma_m = -1.0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  EXPECT_NO_THROW(EkfParams::crazyflieLike().validate());
  EXPECT_NO_THROW(EkfParams::tdoaOnly().validate());
  EXPECT_EQ(parseRobustLoss("cauchy"), RobustLoss::kCauchy);
  EXPECT_THROW(parseRobustLoss("l1"), std::invalid_argument);
}

}  // namespace
}  // namespace uwb
