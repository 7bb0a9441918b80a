/** @file FloorConstraintTest.cpp
 *  @brief The floor in the air (docs/math/filter.md F22): the filter's belief truncated to z ≥ floor by the half-line
 *         node (docs/math/message-passing.md G23), against Monte Carlo samples of the truncated joint Gaussian.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "uwb/filter/Ekf.h"
#include "uwb/graph/HalfLine.h"

namespace uwb {
namespace {

/// A random 15 × 15 covariance whose height is uncertain (σ_z ≈ 0.6 m) and correlated with the other states.
ErrMat correlatedCovariance(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  ErrMat A;
  for (int i = 0; i < kDim; ++i)
    for (int j = 0; j < kDim; ++j) A(i, j) = n(rng);
  ErrMat P = A * A.transpose() / kDim;
  P.diagonal().array() += 0.05;
  const double s = 0.6 / std::sqrt(P(kPos + 2, kPos + 2));
  P.row(kPos + 2) *= s;
  P.col(kPos + 2) *= s;
  return P;
}

TEST(Ekf, FloorConstraintGivesTheMomentsOfTheTruncatedJointGaussian) {
  for (unsigned seed : {3u, 8u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    // GIVEN a belief whose height lies 0.3 m below the floor (z = 0) with σ_z = 0.6 m, correlated with everything else
    EkfParams params = EkfParams::defaults();
    params.range_bias_sigma_m = 0.0;
    Ekf ekf(params);
    NavState x0;
    x0.w_p_b = Vec3(1.0, -0.5, -0.3);
    x0.w_v_b = Vec3(0.2, 0.0, -0.4);
    const ErrMat P0 = correlatedCovariance(seed);
    ekf.initialize(x0, P0);
    // WHEN the constraint z ≥ 0 is applied
    ASSERT_TRUE(ekf.constrainPositionAbove(2, 0.0));
    // THEN the height has the moments of its truncated marginal (G23a) ...
    const TruncatedMoments t = truncatedBelow(-0.3, P0(kPos + 2, kPos + 2), 0.0);
    EXPECT_NEAR(ekf.state().w_p_b.z(), t.mean, 1e-12);
    EXPECT_NEAR(ekf.covariance()(kPos + 2, kPos + 2), t.var, 1e-12);
    // ... and position and velocity have the mean and covariance of samples of the joint Gaussian with z ≥ 0
    const Eigen::LLT<ErrMat> llt(P0);
    const ErrMat L = llt.matrixL();
    std::mt19937 rng(100 + seed);
    std::normal_distribution<double> n(0.0, 1.0);
    using Vec6 = Eigen::Matrix<double, 6, 1>;
    using Mat6 = Eigen::Matrix<double, 6, 6>;
    Vec6 sum = Vec6::Zero();
    Mat6 sum2 = Mat6::Zero();
    int kept = 0;
    for (int i = 0; i < 400000; ++i) {
      ErrVec e;
      for (int k = 0; k < kDim; ++k) e(k) = n(rng);
      const ErrVec dx = L * e;
      if (x0.w_p_b.z() + dx(kPos + 2) < 0.0) continue;
      const Vec6 pv = dx.head<6>();
      sum += pv;
      sum2 += pv * pv.transpose();
      ++kept;
    }
    const Vec6 mean = sum / kept;
    const Mat6 cov = sum2 / kept - mean * mean.transpose();
    Vec6 got_mean;
    got_mean << ekf.state().w_p_b - x0.w_p_b, ekf.state().w_v_b - x0.w_v_b;
    const Mat6 got_cov = ekf.covariance().topLeftCorner<6, 6>();
    for (int i = 0; i < 6; ++i) {
      const double se = std::sqrt(cov(i, i) / kept);
      EXPECT_NEAR(got_mean(i), mean(i), 5.0 * se) << "mean " << i;
      for (int j = 0; j < 6; ++j) {
        const double se_c = std::sqrt((cov(i, i) * cov(j, j) + cov(i, j) * cov(i, j)) / kept);
        EXPECT_NEAR(got_cov(i, j), cov(i, j), 5.0 * se_c) << "cov " << i << "," << j;
      }
    }
    // the old rule (z = floor ± 0.02 m) would have left σ_z ≈ 0.02 m; the truncated belief keeps most of its width
    EXPECT_GT(std::sqrt(got_cov(2, 2)), 0.3);
  }
}

TEST(Ekf, FloorConstraintLeavesABeliefWellAboveTheFloorAlone) {
  Ekf ekf(EkfParams::defaults());
  NavState x0;
  x0.w_p_b = Vec3(0.0, 0.0, 1.0);
  ekf.initialize(x0, ErrMat::Identity() * 0.01);
  EXPECT_FALSE(ekf.constrainPositionAbove(2, 0.0));
  EXPECT_EQ(ekf.state().w_p_b, x0.w_p_b);
  EXPECT_THROW(ekf.constrainPositionAbove(3, 0.0), std::invalid_argument);
}

TEST(Ekf, ConstraintFromAboveIsTheMirrorOfTheConstraintFromBelow) {
  // GIVEN a correlated belief, and the same belief with every state's sign flipped (δx → −δx keeps P)
  const ErrMat P0 = correlatedCovariance(5);
  EkfParams params = EkfParams::defaults();
  params.range_bias_sigma_m = 0.0;
  NavState x0, x0m;
  x0.w_p_b = Vec3(1.0, -0.5, 1.3);
  x0.w_v_b = Vec3(0.2, 0.0, 0.4);
  x0m.w_p_b = -x0.w_p_b;
  x0m.w_v_b = -x0.w_v_b;
  Ekf below(params), above(params);
  below.initialize(x0, P0);
  above.initialize(x0m, P0);
  // WHEN one is held to z ≤ 1.0 and the other to −z ≥ −1.0 (F26's bound, G23 on the negated height)
  ASSERT_TRUE(below.constrainPositionBelow(2, 1.0));
  ASSERT_TRUE(above.constrainPositionAbove(2, -1.0));
  // THEN the means are mirror images and the covariances equal, and the height has the moments of its marginal
  // truncated above
  EXPECT_LT((below.state().w_p_b + above.state().w_p_b).norm(), 1e-12);
  EXPECT_LT((below.state().w_v_b + above.state().w_v_b).norm(), 1e-12);
  EXPECT_LT((below.covariance() - above.covariance()).cwiseAbs().maxCoeff(), 1e-12);
  const TruncatedMoments t = truncatedBelow(-1.3, P0(kPos + 2, kPos + 2), -1.0);
  EXPECT_NEAR(below.state().w_p_b.z(), -t.mean, 1e-12);
  EXPECT_NEAR(below.covariance()(kPos + 2, kPos + 2), t.var, 1e-12);
  EXPECT_LT(below.state().w_p_b.z(), 1.0);
  EXPECT_THROW(below.constrainPositionBelow(-1, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace uwb
