/** @file TdoaLinearizationTest.cpp
 *  @brief Paper eq. (4) linearization (docs/math/measurement.md M6–M8).
 */
#include "uwb/model/TdoaLinearization.h"

#include <gtest/gtest.h>

#include <random>

#include "uwb/model/TdoaModel.h"

namespace uwb {
namespace {

double exactTdoa(const Vec3& x_k, const Vec3& x_i, const Vec3& x_j) { return (x_k - x_i).norm() - (x_k - x_j).norm(); }

Vec3 randomVec(std::mt19937& rng, double scale) {
  std::normal_distribution<double> n(0.0, scale);
  return Vec3(n(rng), n(rng), n(rng));
}

TEST(TdoaLinearization, ExactAtTheLinearizationPoint) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    // GIVEN random positions of agent k and anchors i, j
    std::mt19937 rng(seed);
    const Vec3 x_k = randomVec(rng, 2.0), x_i = randomVec(rng, 3.0), x_j = randomVec(rng, 3.0);
    // WHEN we linearize there
    const auto lin = linearizeTdoa(x_k, x_i, x_j);
    ASSERT_TRUE(lin);
    // THEN the affine model reproduces the exact TDoA (eq. 2) and B1, B2 are unit row vectors
    EXPECT_NEAR(lin->evaluate(x_k, x_i, x_j), exactTdoa(x_k, x_i, x_j), 1e-12);
    EXPECT_NEAR(lin->B1.norm(), 1.0, 1e-12);
    EXPECT_NEAR(lin->B2.norm(), 1.0, 1e-12);
    EXPECT_NEAR(lin->D, 0.0, 1e-12);  // M7: the norm is 1-homogeneous, so D vanishes (up to rounding)
  }
}

TEST(TdoaLinearization, FirstOrderAccurateNearby) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    // GIVEN a linearization and a random direction of perturbation of all three positions
    std::mt19937 rng(100 + seed);
    const Vec3 x_k = randomVec(rng, 2.0), x_i = randomVec(rng, 3.0) + Vec3(4, 0, 0), x_j = randomVec(rng, 3.0) - Vec3(4, 0, 0);
    const auto lin = linearizeTdoa(x_k, x_i, x_j);
    ASSERT_TRUE(lin);
    const Vec3 dk = randomVec(rng, 1.0), di = randomVec(rng, 1.0), dj = randomVec(rng, 1.0);
    // WHEN we shrink the perturbation by 10
    const auto err = [&](double h) {
      return std::abs(lin->evaluate(x_k + h * dk, x_i + h * di, x_j + h * dj) - exactTdoa(x_k + h * dk, x_i + h * di, x_j + h * dj));
    };
    const double e1 = err(1e-2), e2 = err(1e-3);
    // THEN the error shrinks by ~100 (second order remainder) and is small
    EXPECT_LT(e2, 1e-5);
    EXPECT_LT(e2, 0.02 * e1 + 1e-13);
  }
}

TEST(TdoaLinearization, MatchesModelJacobiansWithUtilOrder) {
  // GIVEN the UTIL convention z = |p − a_B| − |p − a_A| ⇒ x_i = a_B, x_j = a_A
  const Vec3 p(0.5, 1.0, 1.2), a(3.0, -2.0, 0.2), b(-3.0, 2.5, 2.8);
  TdoaModelParams params;
  params.b_t_tag = Vec3::Zero();
  TdoaJacobians J;
  const auto z = evaluateTdoa(p, Quat::Identity(), a, b, params, &J);
  // WHEN we linearize with (x_k, x_i, x_j) = (p, b, a)
  const auto lin = linearizeTdoa(p, b, a);
  ASSERT_TRUE(z && lin);
  // THEN B12 = ∂z/∂p, −B1 = ∂z/∂a_B, B2 = ∂z/∂a_A and the value agrees
  EXPECT_NEAR(lin->evaluate(p, b, a), *z, 1e-12);
  EXPECT_LT((lin->B12() - J.J_z_p_b).norm(), 1e-12);
  EXPECT_LT((-lin->B1 - J.J_z_anchor_b).norm(), 1e-12);
  EXPECT_LT((lin->B2 - J.J_z_anchor_a).norm(), 1e-12);
}

TEST(TdoaLinearization, TagAtAnchorIsDegenerate) {
  // GIVEN x_k on anchor i (then on anchor j), WHEN we linearize, THEN nullopt
  const Vec3 x_i(1, 2, 3), x_j(-1, 0, 2);
  EXPECT_FALSE(linearizeTdoa(x_i, x_i, x_j));
  EXPECT_FALSE(linearizeTdoa(x_j, x_i, x_j));
  EXPECT_FALSE(linearizeTdoa(x_i + Vec3(1e-9, 0, 0), x_i, x_j));
}

}  // namespace
}  // namespace uwb
