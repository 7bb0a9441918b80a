/** @file TdoaModelTest.cpp
 *  @brief TDoA model (docs/math/measurement.md M1–M5): values, analytic Jacobians vs central differences,
 *         degenerate geometry.
 */
#include "uwb/model/TdoaModel.h"

#include <gtest/gtest.h>

#include <random>

#include "support/TestSupport.h"

namespace uwb {
namespace {

struct Scene {
  Vec3 w_p_b;
  Quat w_q_b;
  Vec3 a;
  Vec3 b;
};

Scene randomScene(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  Scene s;
  s.w_p_b = Vec3(u(rng), u(rng), 0.5 * u(rng) + 1.5);
  s.w_q_b = Quat(Eigen::AngleAxisd(u(rng), Vec3(u(rng), u(rng), u(rng)).normalized()));
  s.a = Vec3(u(rng), u(rng), u(rng)) * 1.5;
  s.b = Vec3(u(rng), u(rng), u(rng)) * 1.5;
  return s;
}

constexpr double kTol = 1e-7;

TEST(TdoaModel, ValueFollowsUtilSignConvention) {
  // GIVEN a body at the origin with zero lever arm and anchors A, B at known distances
  TdoaModelParams params;
  params.b_t_tag = Vec3::Zero();
  const Vec3 a(3.0, 0.0, 0.0), b(0.0, 5.0, 0.0);
  // WHEN we evaluate the TDoA
  const std::optional<double> z = evaluateTdoa(Vec3::Zero(), Quat::Identity(), a, b, params);
  // THEN z = |p − a_B| − |p − a_A| = 5 − 3, and predictTdoa agrees
  ASSERT_TRUE(z);
  EXPECT_NEAR(*z, 2.0, 1e-15);
  EXPECT_NEAR(predictTdoa(Vec3::Zero(), Quat::Identity(), Vec3::Zero(), a, b), 2.0, 1e-15);
}

TEST(TdoaModel, LeverArmDefaultsToUtilTagOffset) {
  // GIVEN default params, WHEN we read the lever arm, THEN it is the UTIL tag offset and validates
  const TdoaModelParams params;
  EXPECT_EQ(params.b_t_tag, kUtilTagOffset_b);
  EXPECT_NO_THROW(params.validate());
  TdoaModelParams bad;
  bad.min_range_m = 0.0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

TEST(TdoaModel, JacobiansMatchCentralDifferences) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    // GIVEN a random pose, random anchors and a (deliberately large) lever arm
    const Scene s = randomScene(seed);
    TdoaModelParams params;
    params.b_t_tag = Vec3(0.3, -0.2, 0.25);
    // WHEN we compute analytic and numerical Jacobians
    TdoaJacobians J;
    ASSERT_TRUE(evaluateTdoa(s.w_p_b, s.w_q_b, s.a, s.b, params, &J));
    const auto z_of_p = [&](const VecX& p) {
      return VecX::Constant(1, *evaluateTdoa(p, s.w_q_b, s.a, s.b, params));
    };
    const auto z_of_q = [&](const Quat& q) { return VecX::Constant(1, *evaluateTdoa(s.w_p_b, q, s.a, s.b, params)); };
    const auto z_of_a = [&](const VecX& a) { return VecX::Constant(1, *evaluateTdoa(s.w_p_b, s.w_q_b, a, s.b, params)); };
    const auto z_of_b = [&](const VecX& b) { return VecX::Constant(1, *evaluateTdoa(s.w_p_b, s.w_q_b, s.a, b, params)); };
    const test::JacobianCheck c_p = test::checkJacobian(z_of_p, s.w_p_b, J.J_z_p_b);
    const test::JacobianCheck c_q = test::checkJacobianRotation(z_of_q, s.w_q_b, J.J_z_dtheta);
    const test::JacobianCheck c_a = test::checkJacobian(z_of_a, s.a, J.J_z_anchor_a);
    const test::JacobianCheck c_b = test::checkJacobian(z_of_b, s.b, J.J_z_anchor_b);
    // THEN they agree (right, body-frame attitude perturbation q ⊗ exp(δθ))
    EXPECT_LT(c_p.max_abs_error, kTol) << c_p;
    EXPECT_LT(c_q.max_abs_error, kTol) << c_q;
    EXPECT_LT(c_a.max_abs_error, kTol) << c_a;
    EXPECT_LT(c_b.max_abs_error, kTol) << c_b;
  }
}

TEST(TdoaModel, TagPositionJacobianAttitudeMatchesCentralDifferences) {
  // GIVEN a rotation and a lever arm
  const Quat q(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  const Vec3 b_t(0.1, -0.05, 0.2);
  // WHEN we differentiate p_tag = w_p_b + R b_t w.r.t. the right perturbation
  const test::JacobianCheck c = test::checkJacobianRotation(
      [&](const Quat& qq) { return VecX(tagPosition(Vec3::Zero(), qq, b_t)); }, q, tagPositionJacobianAttitude(q, b_t));
  // THEN it equals −R [b_t]×
  EXPECT_LT(c.max_abs_error, kTol) << c;
}

TEST(TdoaModel, RangeGradientMatchesCentralDifferences) {
  // GIVEN p and a, WHEN we differentiate |p − a|, THEN the analytic gradient (M3) matches
  const Vec3 p(1.0, -2.0, 0.5), a(-0.3, 0.4, 2.0);
  RowVec3 J;
  range(p, a, &J);
  const test::JacobianCheck c = test::checkJacobian([&](const VecX& x) { return VecX::Constant(1, range(x, a)); }, p, J);
  EXPECT_LT(c.max_abs_error, kTol) << c;
}

TEST(TdoaModel, TagOnAnchorIsDegenerate) {
  // GIVEN a pose whose tag sits exactly on anchor A (and then on anchor B)
  TdoaModelParams params;
  const Quat q(Eigen::AngleAxisd(0.3, Vec3::UnitZ()));
  const Vec3 w_p_b(1.0, 2.0, 1.0);
  const Vec3 tag = tagPosition(w_p_b, q, params.b_t_tag);
  const Vec3 other(4.0, -1.0, 2.5);
  // WHEN we evaluate the model with Jacobians
  TdoaJacobians J;
  // THEN the outcome is nullopt, never a NaN
  EXPECT_FALSE(evaluateTdoa(w_p_b, q, tag, other, params, &J));
  EXPECT_FALSE(evaluateTdoa(w_p_b, q, other, tag, params, &J));
  EXPECT_FALSE(evaluateTdoa(w_p_b, q, tag + Vec3(1e-8, 0, 0), other, params, &J));
  EXPECT_TRUE(evaluateTdoa(w_p_b, q, tag + Vec3(1e-3, 0, 0), other, params, &J));
}

}  // namespace
}  // namespace uwb
