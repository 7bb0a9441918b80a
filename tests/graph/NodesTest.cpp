/** @file NodesTest.cpp
 *  @brief Each Loeliger node rule (docs/math/message-passing.md G3–G10) against a brute-force product or
 *         marginal of Gaussians.
 */
#include "uwb/graph/Nodes.h"

#include <gtest/gtest.h>

#include "GraphTestUtil.h"

namespace uwb {
namespace {

using namespace graphtest;

constexpr double kTol = 1e-9;

TEST(Nodes, EqualityIsTheNormalizedProductOfDensities) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    // GIVEN two random Gaussian messages on the same variable
    std::mt19937 rng(seed);
    const Eigen::Index n = 1 + seed % 5;
    const Moments x = randomMoments(rng, n), y = randomMoments(rng, n);
    // WHEN we combine them in the equality node (information form G3, moment forms G4, G5)
    const Information zi = equality(*toInformation(x), *toInformation(y));
    const auto zm = toMoments(zi);
    const auto z_mixed = equality(x, *toInformation(y));
    const auto z_moments = equality(x, y);
    ASSERT_TRUE(zm && z_mixed && z_moments);
    // THEN log N(t; m_Z, V_Z) − log µ_X(t) − log µ_Y(t) is the same constant at every t (normalized product)
    const VecX t0 = randomVector(rng, n);
    const double c0 = logMoments(*zm, t0) - logMoments(x, t0) - logMoments(y, t0);
    for (int k = 0; k < 5; ++k) {
      const VecX t = randomVector(rng, n, 3.0);
      EXPECT_NEAR(logMoments(*zm, t) - logMoments(x, t) - logMoments(y, t), c0, 1e-8);
    }
    // AND the brute-force dense joint (X, X − Y) conditioned on X − Y = 0 gives the same moments
    MatX T(2 * n, 2 * n);
    T << MatX::Identity(n, n), MatX::Zero(n, n), MatX::Identity(n, n), -MatX::Identity(n, n);
    MatX Vxy = MatX::Zero(2 * n, 2 * n);
    Vxy.topLeftCorner(n, n) = x.V;
    Vxy.bottomRightCorner(n, n) = y.V;
    VecX mxy(2 * n);
    mxy << x.m, y.m;
    const Moments brute = condition(T * mxy, T * Vxy * T.transpose(), n, VecX::Zero(n));
    EXPECT_LT(maxAbsDifference(*zm, brute), kTol);
    EXPECT_LT(maxAbsDifference(*z_mixed, brute), kTol);
    EXPECT_LT(maxAbsDifference(*z_moments, brute), kTol);
  }
}

TEST(Nodes, EqualityWithSingularInformationMatchesConditioning) {
  for (unsigned seed = 1; seed <= 10; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    // GIVEN a moment-form prior X (n = 4) and an observation y = H x + v of rank 2 (W_Y = Hᵀ R⁻¹ H singular)
    std::mt19937 rng(seed);
    const Moments x = randomMoments(rng, 4);
    const MatX H = randomMatrix(rng, 2, 4);
    const MatX R = randomSpd(rng, 2);
    const VecX y = randomVector(rng, 2);
    const Information msg = multiplyBackward(H, *toInformation(Moments{y, R}));  // G7
    // WHEN we combine with the mixed equality rule (G4)
    const auto z = equality(x, msg);
    ASSERT_TRUE(z);
    // THEN it equals conditioning the dense joint of (x, H x + v) on y
    MatX V(6, 6);
    V << x.V, x.V * H.transpose(), H * x.V, H * x.V * H.transpose() + R;
    VecX m(6);
    m << x.m, H * x.m;
    const Moments brute = condition(m, V, 4, y);
    EXPECT_LT(maxAbsDifference(*z, brute), kTol);
    // AND the Table 4 composite (G10) gives the same
    const auto z10 = equalityMultiply(x, H, Moments{y, R});
    ASSERT_TRUE(z10);
    EXPECT_LT(maxAbsDifference(*z10, brute), kTol);
  }
}

TEST(Nodes, MultiplyForwardIsTheMarginalOfTheJoint) {
  for (unsigned seed = 1; seed <= 10; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    // GIVEN X ~ N(m, V) and Y = A X
    std::mt19937 rng(seed);
    const Moments x = randomMoments(rng, 4);
    const MatX A = randomMatrix(rng, 2, 4);
    // WHEN we pass forward (G6)
    const Moments yv = multiplyForward(A, x);
    // THEN it is the Y-marginal of the dense joint [X; Y] = [I; A] X
    MatX L(6, 4);
    L << MatX::Identity(4, 4), A;
    const MatX Vj = L * x.V * L.transpose();
    const VecX mj = L * x.m;
    EXPECT_LT(maxAbs(yv.m - mj.tail(2)), kTol);
    EXPECT_LT(maxAbs(yv.V - Vj.bottomRightCorner(2, 2)), kTol);
  }
}

TEST(Nodes, MultiplyBackwardIsTheLikelihoodOfX) {
  for (unsigned seed = 1; seed <= 10; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    // GIVEN a message µ_Y = N(m_Y, V_Y) on Y = A X (A: 2×4, so the backward message is singular)
    std::mt19937 rng(seed);
    const Moments y = randomMoments(rng, 2);
    const MatX A = randomMatrix(rng, 2, 4);
    // WHEN we pass backward (G7)
    const Information xb = multiplyBackward(A, *toInformation(y));
    // THEN log µ_X(x) − log N(A x; m_Y, V_Y) is constant in x
    const VecX x0 = randomVector(rng, 4);
    const double c0 = logInformation(xb, x0) - logMoments(y, A * x0);
    for (int k = 0; k < 5; ++k) {
      const VecX x = randomVector(rng, 4, 3.0);
      EXPECT_NEAR(logInformation(xb, x) - logMoments(y, A * x), c0, 1e-8);
    }
  }
}

TEST(Nodes, AdditionForwardAndBackwardAreMarginalsOfTheJoint) {
  for (unsigned seed = 1; seed <= 10; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    // GIVEN independent X, Y and Z = X + Y
    std::mt19937 rng(seed);
    const Moments x = randomMoments(rng, 3), y = randomMoments(rng, 3), z = randomMoments(rng, 3);
    // WHEN we pass forward (G8) and backward (G9)
    const Moments zf = additionForward(x, y);
    const Moments xb = additionBackward(z, y);
    // THEN the forward message is the marginal of [I I] [X; Y] and the backward message of X = Z − Y is the
    //      marginal of [I −I] [Z; Y]
    MatX Vxy = MatX::Zero(6, 6);
    Vxy.topLeftCorner(3, 3) = x.V;
    Vxy.bottomRightCorner(3, 3) = y.V;
    MatX S(3, 6);
    S << MatX::Identity(3, 3), MatX::Identity(3, 3);
    EXPECT_LT(maxAbs(zf.m - (x.m + y.m)), kTol);
    EXPECT_LT(maxAbs(zf.V - S * Vxy * S.transpose()), kTol);
    MatX Vzy = MatX::Zero(6, 6);
    Vzy.topLeftCorner(3, 3) = z.V;
    Vzy.bottomRightCorner(3, 3) = y.V;
    MatX Dm(3, 6);
    Dm << MatX::Identity(3, 3), -MatX::Identity(3, 3);
    EXPECT_LT(maxAbs(xb.m - (z.m - y.m)), kTol);
    EXPECT_LT(maxAbs(xb.V - Dm * Vzy * Dm.transpose()), kTol);
  }
}

TEST(Nodes, AdditionBackwardConstantShiftsTheDensity) {
  // GIVEN a singular information message on Z and Z = X + c
  std::mt19937 rng(5);
  const VecX b = randomVector(rng, 3);
  const Information z{b * 1.7, b * b.transpose() * 2.0};
  const VecX c = randomVector(rng, 3);
  // WHEN we pass it backward to X (G9')
  const Information x = additionBackwardConstant(z, c);
  // THEN µ_X(x) ∝ µ_Z(x + c)
  const VecX x0 = randomVector(rng, 3);
  const double c0 = logInformation(x, x0) - logInformation(z, x0 + c);
  for (int k = 0; k < 5; ++k) {
    const VecX t = randomVector(rng, 3, 2.0);
    EXPECT_NEAR(logInformation(x, t) - logInformation(z, t + c), c0, 1e-10);
  }
}

TEST(Nodes, ZeroVarianceMomentMessageIsAHardConstraint) {
  // GIVEN a prior X and an exact observation Y = A X (V_Y = 0)
  std::mt19937 rng(11);
  const Moments x = randomMoments(rng, 3);
  const MatX A = randomMatrix(rng, 1, 3);
  const Moments y{VecX::Constant(1, 0.4), MatX::Zero(1, 1)};
  // WHEN we use the Table 4 composite (G10)
  const auto z = equalityMultiply(x, A, y);
  // THEN the posterior satisfies A m_Z = m_Y exactly and has zero variance along A
  ASSERT_TRUE(z);
  EXPECT_NEAR((A * z->m)(0), 0.4, 1e-12);
  EXPECT_NEAR((A * z->V * A.transpose())(0, 0), 0.0, 1e-12);
  // AND an exact observation of an exact prior along A is refused (G = 0⁻¹)
  const Moments exact{VecX::Zero(3), MatX::Zero(3, 3)};
  EXPECT_FALSE(equalityMultiply(exact, A, y));
}

TEST(Nodes, DimensionMismatchThrows) {
  // GIVEN messages of different dimensions, WHEN combined, THEN std::invalid_argument
  const Moments a{VecX::Zero(2), MatX::Identity(2, 2)};
  const Moments b{VecX::Zero(3), MatX::Identity(3, 3)};
  EXPECT_THROW(additionForward(a, b), std::invalid_argument);
  EXPECT_THROW(multiplyForward(MatX::Identity(3, 3), a), std::invalid_argument);
  EXPECT_THROW(equality(*toInformation(a), *toInformation(b)), std::invalid_argument);
}

}  // namespace
}  // namespace uwb
