/** @file TrajectoryMetricsTest.cpp
 *  @brief computeTrajectoryMetrics (the RMSE every result is quoted in) against hand-computed cases.
 *
 *  Estimate: t = 0, 1, 2 s at (0, 0, 0), (2, 0, 0), (2, 2, 0). Ground truth and the interpolated estimate:
 *    t = −1   outside the estimate                       → not compared
 *    t = 0.5  true (1, 0, 0.2),   est (1, 0, 0)          → error (0, 0, −0.2),     |e| = 0.2,  on the ground
 *    t = 1    true (2, 0, 0.3),   est (2, 0, 0)          → error (0, 0, −0.3),     |e| = 0.3,  on the ground (z = 0.3
 *                                                          is not above the threshold)
 *    t = 1.5  true (1.7, 0.6, 1), est (2, 1, 0)          → error (0.3, 0.4, −1),   |e| = √1.25, airborne
 *    t = 2    true (2, 2, 0.5),   est (2, 2, 0)          → error (0, 0, −0.5),     |e| = 0.5,  airborne
 *    t = 2.5  outside the estimate                       → not compared
 */
#include <gtest/gtest.h>

#include <cmath>

#include "uwb/eval/EstimateChecks.h"
#include "uwb/eval/TrajectoryMetrics.h"

namespace uwb {
namespace {

Trajectory handEstimate() {
  Trajectory est(3);
  est[0].t_s = 0.0, est[0].w_p_b = Vec3(0, 0, 0);
  est[1].t_s = 1.0, est[1].w_p_b = Vec3(2, 0, 0);
  est[2].t_s = 2.0, est[2].w_p_b = Vec3(2, 2, 0);
  return est;
}

std::vector<PoseSample> handTruth() {
  const std::pair<double, Vec3> rows[] = {{-1.0, Vec3(0, 0, 1)},    {0.5, Vec3(1, 0, 0.2)},   {1.0, Vec3(2, 0, 0.3)},
                                          {1.5, Vec3(1.7, 0.6, 1)}, {2.0, Vec3(2, 2, 0.5)},   {2.5, Vec3(2, 2, 1)}};
  std::vector<PoseSample> out;
  for (const auto& [t, p] : rows) {
    PoseSample s;
    s.t_s = t;
    s.w_p_b = p;
    out.push_back(s);
  }
  return out;
}

TEST(TrajectoryMetrics, GivenAHandComputedFlightWhenComparedThenEveryStatisticMatches) {
  // GIVEN the estimate and ground truth of the file comment, estimate samples 1 s apart (gap limit 2 s)
  TrajectoryMetricsParams params;
  params.max_interp_gap_s = 2.0;
  // WHEN computing the metrics
  const TrajectoryMetrics m = computeTrajectoryMetrics(handEstimate(), handTruth(), params);
  // THEN four instants are compared, two are outside the estimate
  ASSERT_EQ(m.samples.size(), 4u);
  EXPECT_EQ(m.n_truth_not_covered, 2u);
  const double tol = 1e-12;
  EXPECT_LT((m.samples[2].w_p_est - Vec3(2, 1, 0)).norm(), tol);
  EXPECT_LT((m.samples[2].error_m - Vec3(0.3, 0.4, -1.0)).norm(), tol);
  EXPECT_FALSE(m.samples[0].airborne);
  EXPECT_FALSE(m.samples[1].airborne);  // z = 0.3 m is not above kAirborneMinZ_m
  EXPECT_TRUE(m.samples[2].airborne);
  EXPECT_TRUE(m.samples[3].airborne);
  // whole flight: squared errors per axis x 0.09, y 0.16, z 0.04 + 0.09 + 1 + 0.25 = 1.38
  EXPECT_EQ(m.whole.n, 4u);
  EXPECT_NEAR(m.whole.rmse_axis_m.x(), std::sqrt(0.09 / 4), tol);
  EXPECT_NEAR(m.whole.rmse_axis_m.y(), std::sqrt(0.16 / 4), tol);
  EXPECT_NEAR(m.whole.rmse_axis_m.z(), std::sqrt(1.38 / 4), tol);
  EXPECT_NEAR(m.whole.rmse_m, std::sqrt((0.09 + 0.16 + 1.38) / 4), tol);
  EXPECT_NEAR(m.whole.mean_m, (0.2 + 0.3 + std::sqrt(1.25) + 0.5) / 4, tol);
  // sorted norms 0.2, 0.3, 0.5, √1.25; percentile q at position q·3, linearly interpolated
  EXPECT_NEAR(m.whole.p50_m, 0.5 * 0.3 + 0.5 * 0.5, tol);
  EXPECT_NEAR(m.whole.p90_m, 0.3 * 0.5 + 0.7 * std::sqrt(1.25), tol);
  EXPECT_NEAR(m.whole.max_m, std::sqrt(1.25), tol);
  // airborne: the last two instants
  EXPECT_EQ(m.airborne.n, 2u);
  EXPECT_NEAR(m.airborne.rmse_axis_m.x(), std::sqrt(0.09 / 2), tol);
  EXPECT_NEAR(m.airborne.rmse_axis_m.z(), std::sqrt((1.0 + 0.25) / 2), tol);
  EXPECT_NEAR(m.airborne.rmse_m, std::sqrt((1.25 + 0.25) / 2), tol);
  EXPECT_NEAR(m.airborne.p50_m, 0.5 * 0.5 + 0.5 * std::sqrt(1.25), tol);
}

TEST(TrajectoryMetrics, GivenATimeWindowThenTheAirborneRmseCountsOnlyItsAirborneInstants) {
  // GIVEN the hand-computed flight (airborne at t = 1.5 s, |e| = √1.25, and t = 2 s, |e| = 0.5)
  TrajectoryMetricsParams params;
  params.max_interp_gap_s = 2.0;
  const TrajectoryMetrics m = computeTrajectoryMetrics(handEstimate(), handTruth(), params);
  // WHEN taking the RMSE over windows, THEN the bounds are inclusive, instants on the ground never count, and a
  // window without airborne instants has none
  EXPECT_NEAR(airborneRmseInWindow(m, 0.0, 2.0), m.airborne.rmse_m, 1e-12);
  EXPECT_NEAR(airborneRmseInWindow(m, 1.5, 1.5), std::sqrt(1.25), 1e-12);
  EXPECT_NEAR(airborneRmseInWindow(m, 1.6, 5.0), 0.5, 1e-12);
  EXPECT_TRUE(std::isnan(airborneRmseInWindow(m, 0.0, 1.2)));
}

TEST(EstimateChecks, GivenTheHandComputedFlightThenTheLargestErrorBeforeTheFirstAirborneInstantIsReported) {
  // GIVEN the hand-computed flight: on the ground at t = 0.5 s (|e| = 0.2) and t = 1 s (|e| = 0.3), airborne from
  // t = 1.5 s (|e| = √1.25)
  TrajectoryMetricsParams params;
  params.max_interp_gap_s = 2.0;
  const TrajectoryMetrics m = computeTrajectoryMetrics(handEstimate(), handTruth(), params);
  // WHEN checking the estimate, THEN the largest error before take-off is 0.3 m, not the airborne 1.1 m
  EXPECT_NEAR(checkEstimate(handEstimate(), m).max_error_before_takeoff_m, 0.3, 1e-12);
  // and a flight that is airborne from its first compared instant has none
  TrajectoryMetrics air = m;
  for (PositionErrorSample& s : air.samples) s.airborne = true;
  EXPECT_TRUE(std::isnan(checkEstimate(handEstimate(), air).max_error_before_takeoff_m));
}

TEST(TrajectoryMetrics, GivenAGapInTheEstimateWhenComparedThenInstantsInTheGapAreNotCompared) {
  // GIVEN estimate samples 1 s apart and the default gap limit (0.1 s)
  // WHEN computing the metrics
  const TrajectoryMetrics m = computeTrajectoryMetrics(handEstimate(), handTruth());
  // THEN an instant is compared only where the estimate samples around it are within the limit (bracketPose: the
  // sample at or before t and the next one): none but the last estimate sample itself (t = 2 s), error 0.5 m
  ASSERT_EQ(m.samples.size(), 1u);
  EXPECT_EQ(m.n_truth_not_covered, 5u);
  EXPECT_DOUBLE_EQ(m.samples[0].t_s, 2.0);
  EXPECT_NEAR(m.whole.rmse_m, 0.5, 1e-12);
}

TEST(TrajectoryMetrics, GivenNoOverlapThenStatisticsAreZeroNotNan) {
  // GIVEN an empty estimate, WHEN compared, THEN nothing is compared and every statistic is zero
  const TrajectoryMetrics m = computeTrajectoryMetrics({}, handTruth());
  EXPECT_EQ(m.n_truth_not_covered, 6u);
  EXPECT_EQ(m.whole.n, 0u);
  EXPECT_EQ(m.whole.rmse_m, 0.0);
  EXPECT_EQ(m.airborne.max_m, 0.0);
}

}  // namespace
}  // namespace uwb
