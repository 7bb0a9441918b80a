/** @file TdoaNodeTest.cpp
 *  @brief The paper's TDoA node (Fig. 2; docs/math/message-passing.md G11–G14) against conditioning a dense joint
 *         Gaussian of (x_k, x_i, x_j, ε).
 */
#include "uwb/graph/TdoaNode.h"

#include <gtest/gtest.h>

#include "GraphTestUtil.h"
#include "uwb/graph/Nodes.h"

namespace uwb {
namespace {

using namespace graphtest;

constexpr double kTol = 1e-9;

struct NodeScene {
  Moments3 x_k, x_i, x_j;
  double var_m2;
  double z_m;
  TdoaLinearization lin;
};

NodeScene randomNodeScene(unsigned seed) {
  std::mt19937 rng(seed);
  NodeScene s;
  s.x_k = {Vec3(randomVector(rng, 3)), Mat3(randomSpd(rng, 3, 0.05) * 0.1)};
  s.x_i = {Vec3(randomVector(rng, 3) + Vec3(4, 0, 1)), Mat3(randomSpd(rng, 3, 0.01) * 0.01)};
  s.x_j = {Vec3(randomVector(rng, 3) + Vec3(-4, 1, 2)), Mat3(randomSpd(rng, 3, 0.01) * 0.01)};
  s.var_m2 = 0.01 + 0.1 * std::abs(randomVector(rng, 1)[0]);
  s.lin = *linearizeTdoa(s.x_k.m, s.x_i.m, s.x_j.m);
  s.z_m = s.lin.evaluate(s.x_k.m, s.x_i.m, s.x_j.m) + randomVector(rng, 1, 0.3)[0];
  return s;
}

/// Dense joint of w = [x_k; x_i; x_j; ε] and z = D + B12 x_k − B1 x_i + B2 x_j + ε; returns the posterior of the
/// 3-block `which` (0 = k, 1 = i, 2 = j) given z.
Moments bruteForcePosterior(const NodeScene& s, int which) {
  VecX m = VecX::Zero(10);
  m << s.x_k.m, s.x_i.m, s.x_j.m, 0.0;
  MatX V = MatX::Zero(10, 10);
  V.block<3, 3>(0, 0) = s.x_k.V;
  V.block<3, 3>(3, 3) = s.x_i.V;
  V.block<3, 3>(6, 6) = s.x_j.V;
  V(9, 9) = s.var_m2;
  Eigen::RowVectorXd L(10);
  // by segments: GCC 12 reads a comma-initialized 3-vector with a 4-wide AVX load (a -Warray-bounds false positive)
  L.segment<3>(0) = s.lin.B12();
  L.segment<3>(3) = -s.lin.B1;
  L.segment<3>(6) = s.lin.B2;
  L(9) = 1.0;
  MatX T = MatX::Zero(4, 10);  // [x_which; z]
  T.block<3, 3>(0, 3 * which) = Mat3::Identity();
  T.row(3) = L;
  VecX mt = T * m;
  mt(3) += s.lin.D;
  return condition(mt, T * V * T.transpose(), 3, VecX::Constant(1, s.z_m));
}

Moments toDyn(const Moments3& x) { return {x.m, x.V}; }
Information toDyn(const Information3& x) { return {x.xi, x.W}; }

TEST(TdoaNode, MessagesFollowThePaper) {
  // GIVEN a random scene
  const NodeScene s = randomNodeScene(1);
  // WHEN we run the forward pass
  const TdoaNodeMessages msg = tdoaNodeForward(s.lin, s.x_i, s.x_j, s.z_m, s.var_m2);
  // THEN each message is the paper's formula (III-A)
  EXPECT_NEAR(msg.mu3.m, -s.lin.B1.dot(s.x_i.m), 1e-15);
  EXPECT_NEAR(msg.mu3.V, (s.lin.B1 * s.x_i.V * s.lin.B1.transpose())(0, 0), 1e-15);
  EXPECT_NEAR(msg.mu4.m, s.lin.B2.dot(s.x_j.m), 1e-15);
  EXPECT_NEAR(msg.mu4.V, (s.lin.B2 * s.x_j.V * s.lin.B2.transpose())(0, 0), 1e-15);
  EXPECT_NEAR(msg.mu7.m, s.z_m - msg.mu3.m - msg.mu4.m - s.lin.D, 1e-15);
  EXPECT_NEAR(msg.mu7.V, s.var_m2 + msg.mu3.V + msg.mu4.V, 1e-15);
  EXPECT_NEAR(msg.W7 * msg.mu7.V, 1.0, 1e-15);
  EXPECT_NEAR(msg.xi7, msg.W7 * msg.mu7.m, 1e-15);
  EXPECT_LT(maxAbs(msg.mu8.xi - msg.B12.transpose() * msg.xi7), 1e-15);
  EXPECT_LT(maxAbs(msg.mu8.W - msg.B12.transpose() * msg.W7 * msg.B12), 1e-15);
}

TEST(TdoaNode, MessageOnTagIsTheMarginalLikelihood) {
  for (unsigned seed = 1; seed <= 10; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    // GIVEN uncertain anchors and a measurement
    const NodeScene s = randomNodeScene(seed);
    // WHEN we compute µ8 on x_k
    const Information mu8 = toDyn(tdoaNodeForward(s.lin, s.x_i, s.x_j, s.z_m, s.var_m2).mu8);
    // THEN µ8(x) ∝ p(z | x_k = x) with the anchors marginalized: N(z; D + B12 x − B1 m_i + B2 m_j, Σ6 + Σ3 + Σ4)
    const double s7 = s.var_m2 + (s.lin.B1 * s.x_i.V * s.lin.B1.transpose())(0, 0) +
                      (s.lin.B2 * s.x_j.V * s.lin.B2.transpose())(0, 0);
    const auto lik = [&](const Vec3& x) {
      const double r = s.z_m - (s.lin.D + s.lin.B12().dot(x) - s.lin.B1.dot(s.x_i.m) + s.lin.B2.dot(s.x_j.m));
      return -0.5 * r * r / s7;
    };
    const double c0 = logInformation(mu8, s.x_k.m) - lik(s.x_k.m);
    std::mt19937 rng(seed);
    for (int k = 0; k < 5; ++k) {
      const Vec3 x = randomVector(rng, 3, 2.0);
      EXPECT_NEAR(logInformation(mu8, x) - lik(x), c0, 1e-9);
    }
  }
}

TEST(TdoaNode, PosteriorOfTagAndAnchorsMatchesDenseJoint) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    // GIVEN uncertain x_k, x_i, x_j and one TDoA
    const NodeScene s = randomNodeScene(seed);
    // WHEN each variable's prior is combined (equality node G4) with the node's backward message (G13, G14)
    const auto post_k = equality(toDyn(s.x_k), toDyn(tdoaNodeBackwardToK(s.lin, s.x_i, s.x_j, s.z_m, s.var_m2)));
    const auto post_i = equality(toDyn(s.x_i), toDyn(tdoaNodeBackwardToI(s.lin, s.x_k, s.x_j, s.z_m, s.var_m2)));
    const auto post_j = equality(toDyn(s.x_j), toDyn(tdoaNodeBackwardToJ(s.lin, s.x_k, s.x_i, s.z_m, s.var_m2)));
    ASSERT_TRUE(post_k && post_i && post_j);
    // THEN each equals the brute-force conditional of the dense joint given z (exact for the linear model)
    const Moments bk = bruteForcePosterior(s, 0), bi = bruteForcePosterior(s, 1), bj = bruteForcePosterior(s, 2);
    EXPECT_LT(maxAbsDifference(*post_k, bk), kTol);
    EXPECT_LT(maxAbsDifference(*post_i, bi), kTol);
    EXPECT_LT(maxAbsDifference(*post_j, bj), kTol);
  }
}

TEST(TdoaNode, ZeroVarianceAnchorsLeaveOnlyMeasurementNoise) {
  // GIVEN surveyed anchors with zero covariance
  NodeScene s = randomNodeScene(4);
  s.x_i.V.setZero();
  s.x_j.V.setZero();
  // WHEN we run the forward pass
  const TdoaNodeMessages msg = tdoaNodeForward(s.lin, s.x_i, s.x_j, s.z_m, s.var_m2);
  // THEN Σ7 = Σ6 and W8 has rank one (singular) with its null space orthogonal to B12
  EXPECT_DOUBLE_EQ(msg.mu7.V, s.var_m2);
  EXPECT_FALSE(toMoments(toDyn(msg.mu8)));
  const Vec3 null_dir = msg.B12.transpose().cross(Vec3(1.0, 0.3, -0.2));
  EXPECT_LT((msg.mu8.W * null_dir).norm(), 1e-12);
}

TEST(TdoaNode, NonPositiveMeasurementVarianceThrows) {
  // GIVEN a scene, WHEN Σ6 ≤ 0 or NaN, THEN std::invalid_argument (programmer error at the API boundary)
  const NodeScene s = randomNodeScene(2);
  EXPECT_THROW(tdoaNodeForward(s.lin, s.x_i, s.x_j, s.z_m, 0.0), std::invalid_argument);
  EXPECT_THROW(tdoaNodeForward(s.lin, s.x_i, s.x_j, s.z_m, std::nan("")), std::invalid_argument);
}

}  // namespace
}  // namespace uwb
