/** @file CooperativeRangeTest.cpp
 *  @brief Range to an uncertain neighbour (docs/math/message-passing.md G20–G22): analytic Jacobians against
 *         central differences, the covariance-intersection weight against a grid search, and the double-counting
 *         demonstration: two agents that repeatedly fuse each other's beliefs become over-confident with naive
 *         fusion and stay consistent with covariance intersection.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "support/DerivativeChecker.h"
#include "uwb/filter/CooperativeRange.h"
#include "uwb/filter/QuadImuProcess.h"

namespace uwb {
namespace {

NavState tiltedState() {
  NavState x;
  x.w_p_b = Vec3(0.4, -1.2, 1.3);
  x.w_q_b = Quat(Eigen::AngleAxisd(0.3, Vec3(0.2, 0.5, 1.0).normalized()));
  x.w_v_b = Vec3(0.3, 0.1, -0.2);
  return x;
}

TEST(CooperativeRange, JacobiansMatchCentralDifferences) {
  // GIVEN a tilted agent with the UTIL tag lever arm and a neighbour 2 m away
  const NavState x = tiltedState();
  const Vec3 neighbour(2.1, 0.3, 1.8);
  ErrRow a;
  RowVec3 J_j;
  ASSERT_TRUE(cooperativeRangePrediction(x, kUtilTagOffset_b, neighbour, &a, &J_j).has_value());
  // WHEN differentiating h(x ⊞ δx) and h(m_j) numerically
  const auto h_dx = [&](const VecX& dx) {
    return VecX::Constant(1, *cooperativeRangePrediction(boxPlus(x, ErrVec(dx)), kUtilTagOffset_b, neighbour));
  };
  const auto h_mj = [&](const VecX& m) {
    return VecX::Constant(1, *cooperativeRangePrediction(x, kUtilTagOffset_b, Vec3(m)));
  };
  const test::JacobianCheck c1 = test::checkJacobian(h_dx, VecX::Zero(kDim), MatX(a));
  const test::JacobianCheck c2 = test::checkJacobian(h_mj, VecX(neighbour), MatX(J_j));
  // THEN both agree to the difference accuracy
  EXPECT_LT(c1.max_abs_error, 1e-7) << "worst column " << c1.worst_col;
  EXPECT_LT(c2.max_abs_error, 1e-7);
}

TEST(CooperativeRange, TagBeliefIsTheLinearizedTagPosition) {
  // GIVEN a pose covariance; WHEN mapping it to the tag
  const NavState x = tiltedState();
  Eigen::Matrix<double, 6, 6> cov = Eigen::Matrix<double, 6, 6>::Identity() * 0.01;
  cov(0, 4) = cov(4, 0) = 0.003;
  const Moments3 b = tagBelief(x, cov, kUtilTagOffset_b);
  // THEN its Jacobian C = ∂p_tag/∂(δp, δθ) matches differences, and Σ = C cov Cᵀ
  const auto tag = [&](const VecX& d) {
    ErrVec dx = ErrVec::Zero();
    dx.segment<3>(kPos) = d.head<3>();
    dx.segment<3>(kAtt) = d.tail<3>();
    const NavState y = boxPlus(x, dx);
    return VecX(y.w_p_b + y.w_q_b * kUtilTagOffset_b);
  };
  const MatX C = test::numericalJacobian(tag, VecX::Zero(6), {});
  EXPECT_LT((C * cov * C.transpose() - b.V).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((b.m - tag(VecX::Zero(6))).norm(), 1e-12);
}

TEST(CooperativeRange, CovarianceIntersectionWeightMinimisesThePositionTrace) {
  // GIVEN a prior and a neighbour belief; WHEN the update runs at ω and at a grid of other weights
  Ekf base(EkfParams{});
  base.initialize(tiltedState(), initialCovariance(EkfParams{}));
  const Moments3 nb{Vec3(2.1, 0.3, 1.8), Mat3::Identity() * 0.2};
  CooperativeRangeOptions opt;
  opt.gate_sigma = 0.0;
  Ekf ci = base;
  const CooperativeRangeResult r = updateCooperativeRange(ci, nb, 2.0, opt);
  ASSERT_EQ(r.outcome, UpdateOutcome::kApplied);
  ASSERT_GT(r.omega, 0.0);
  ASSERT_LT(r.omega, 1.0);
  const double tr_opt = ci.covariance().block<3, 3>(kPos, kPos).trace();
  ErrRow a;
  RowVec3 J;
  cooperativeRangePrediction(base.state(), opt.b_t_tag, nb.m, &a, &J);
  const double s_dep = (J * nb.V * J.transpose())(0, 0);
  for (double w = 0.02; w < 1.0; w += 0.02) {
    Ekf e = base;
    ASSERT_TRUE(e.inflateAlongPosition(1.0 / w));
    ScalarLinearMessage<kDim> msg;
    msg.a = a;
    msg.y = 0.0;
    msg.var = opt.sigma_m * opt.sigma_m + s_dep / (1.0 - w);
    ASSERT_TRUE(e.correctPositionAttitude(msg).has_value());
    // THEN no grid weight gives a smaller posterior position trace (G21)
    const double tr = e.covariance().block<3, 3>(kPos, kPos).trace();
    EXPECT_GE(tr, tr_opt - 1e-12) << "w = " << w;
  }
}

/// Two agents with only a prior, fusing each other's latest beliefs for `rounds` rounds of ranges; mean position
/// NEES of agent 0 after the last round over Monte-Carlo runs.
double neesAfterExchanges(NeighbourFusion fusion, int rounds) {
  const Vec3 truth[2] = {Vec3(0, 0, 1), Vec3(2, 0.5, 1.2)};
  const double sigma0 = 0.5, sigma_r = 0.1;
  std::mt19937_64 rng(42);
  std::normal_distribution<double> g(0.0, 1.0);
  CooperativeRangeOptions opt;
  opt.b_t_tag = Vec3::Zero();
  opt.sigma_m = sigma_r;
  opt.gate_sigma = 0.0;
  opt.fusion = fusion;
  EkfParams params;
  ErrMat P0 = initialCovariance(params);
  P0.block<3, 3>(kPos, kPos) = Mat3::Identity() * sigma0 * sigma0;
  double nees = 0.0;
  const int runs = 400;
  for (int run = 0; run < runs; ++run) {
    std::vector<Ekf> agents(2, Ekf(params));
    for (int k = 0; k < 2; ++k) {
      NavState x;
      x.w_p_b = truth[k] + sigma0 * Vec3(g(rng), g(rng), g(rng));
      agents[static_cast<std::size_t>(k)].initialize(x, P0);
    }
    for (int r = 0; r < rounds; ++r) {
      // each agent broadcasts its belief, then both measure the range and fuse the other's belief (G20)
      const Moments3 b0{agents[0].state().w_p_b, agents[0].covariance().block<3, 3>(kPos, kPos)};
      const Moments3 b1{agents[1].state().w_p_b, agents[1].covariance().block<3, 3>(kPos, kPos)};
      const double z = (truth[0] - truth[1]).norm() + sigma_r * g(rng);
      updateCooperativeRange(agents[0], b1, z, opt);
      updateCooperativeRange(agents[1], b0, z, opt);
    }
    const Vec3 e = agents[0].state().w_p_b - truth[0];
    nees += e.dot(agents[0].covariance().block<3, 3>(kPos, kPos).ldlt().solve(e));
  }
  return nees / runs;
}

TEST(CooperativeRange, NaiveFusionDoubleCountsAndCovarianceIntersectionDoesNot) {
  // GIVEN two agents that know only a 0.5 m prior of their positions and range each other 50 times, each time
  // fusing the other's latest belief (which already contains its own earlier information)
  // WHEN fused naively and by covariance intersection (G21)
  const double naive = neesAfterExchanges(NeighbourFusion::kNaive, 50);
  const double ci = neesAfterExchanges(NeighbourFusion::kCovarianceIntersection, 50);
  std::printf("mean position NEES after 50 exchanges: naive %.2f, covariance intersection %.2f (ideal ≤ 3)\n", naive,
              ci);
  // THEN naive fusion is over-confident (NEES far above the χ²₃ mean 3; 400 runs: the 99.9 % band of a consistent
  // mean is about 3 ± 0.4), covariance intersection is not (CI is conservative: NEES ≤ 3 within the band)
  EXPECT_GT(naive, 4.0);
  EXPECT_LT(ci, 3.5);
}

}  // namespace
}  // namespace uwb
