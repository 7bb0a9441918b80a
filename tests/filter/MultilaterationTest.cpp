/** @file MultilaterationTest.cpp
 *  @brief Robust Gauss–Newton TDoA multilateration (docs/math/filter.md F16) on hand-computed geometries.
 *
 *  The tag sits at w_p_tag = (0, 0, 1) and the five anchors at whole-number distances from it:
 *    a0 = (3, 4, 1) → 5,  a1 = (−4, 3, 1) → 5,  a2 = (0, 0, 4) → 3,  a3 = (6, 0, 9) → 10,  a4 = (0, −12, 6) → 13,
 *  so the TDoA of a pair (i, j), |p − a_j| − |p − a_i| (paper eq. 2), is a difference of those integers.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "uwb/filter/Multilateration.h"

namespace uwb {
namespace {

AnchorTable handAnchors() {
  AnchorTable t;
  t.set(0, Vec3(3, 4, 1));
  t.set(1, Vec3(-4, 3, 1));
  t.set(2, Vec3(0, 0, 4));
  t.set(3, Vec3(6, 0, 9));
  t.set(4, Vec3(0, -12, 6));
  return t;
}

/// The six TDoAs of a tag at (0, 0, 1), computed by hand from the distances 5, 5, 3, 10, 13.
std::vector<MultilaterationSample> handSamples(const Vec3& w_d_b = Vec3::Zero(), const Quat& w_q_b = Quat::Identity()) {
  const struct {
    int a, b;
    double tdoa_m;
  } pairs[] = {{0, 1, 5.0 - 5.0}, {1, 2, 3.0 - 5.0}, {2, 3, 10.0 - 3.0},
               {3, 4, 13.0 - 10.0}, {4, 0, 5.0 - 13.0}, {0, 2, 3.0 - 5.0}};
  std::vector<MultilaterationSample> out;
  for (const auto& p : pairs) {
    MultilaterationSample s;
    s.z.id_a = p.a;
    s.z.id_b = p.b;
    s.z.tdoa_m = p.tdoa_m;
    s.w_d_b = w_d_b;
    s.w_q_b = w_q_b;
    out.push_back(s);
  }
  return out;
}

TEST(Multilaterate, GivenExactTdoasOfAStaticTagWhenSolvedThenFindsTheTag) {
  // GIVEN six exact TDoAs of a tag at (0, 0, 1), no lever arm, a start 1.7 m away
  // WHEN multilaterating
  const auto res = multilaterate(handSamples(), handAnchors(), Vec3::Zero(), {Vec3(1.0, -1.0, 2.0)});
  // THEN the solution is the tag, every sample is used and the residual vanishes
  ASSERT_TRUE(res);
  EXPECT_LT((res->w_p0 - Vec3(0, 0, 1)).norm(), 1e-9) << res->w_p0.transpose();
  EXPECT_EQ(res->n_used, 6u);
  EXPECT_LT(res->rms_residual_m, 1e-5);  // the residual of the iterate before the last (converged) step
  EXPECT_GE(res->iterations, 2);
}

TEST(Multilaterate, GivenKnownDisplacementsWhenSolvedThenReturnsTheReferencePosition) {
  // GIVEN the same TDoAs, each taken after the body moved by d = (1, 0, 0) since the reference instant
  // WHEN multilaterating
  const auto res = multilaterate(handSamples(Vec3(1, 0, 0)), handAnchors(), Vec3::Zero(), {Vec3(0, 0, 2)});
  // THEN p0 = (0, 0, 1) − d
  ASSERT_TRUE(res);
  EXPECT_LT((res->w_p0 - Vec3(-1, 0, 1)).norm(), 1e-9) << res->w_p0.transpose();
}

TEST(Multilaterate, GivenALeverArmWhenSolvedThenReturnsTheBodyOriginNotTheTag) {
  // GIVEN a tag 0.5 m above the body origin (b_t_tag = (0, 0, 0.5))
  const Vec3 b_t_tag(0, 0, 0.5);
  // WHEN the body is level, THEN the body origin is 0.5 m below the tag: (0, 0, 0.5)
  const auto level = multilaterate(handSamples(), handAnchors(), b_t_tag, {Vec3(0, 0, 2)});
  ASSERT_TRUE(level);
  EXPECT_LT((level->w_p0 - Vec3(0, 0, 0.5)).norm(), 1e-9) << level->w_p0.transpose();
  // WHEN the body is upside down (180° about x, so R b_t_tag = (0, 0, −0.5)), THEN it is 0.5 m above: (0, 0, 1.5)
  const Quat flipped(Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitX()));
  const auto upside_down = multilaterate(handSamples(Vec3::Zero(), flipped), handAnchors(), b_t_tag, {Vec3(0, 0, 2)});
  ASSERT_TRUE(upside_down);
  EXPECT_LT((upside_down->w_p0 - Vec3(0, 0, 1.5)).norm(), 1e-9) << upside_down->w_p0.transpose();
}

TEST(Multilaterate, GivenOneGrossOutlierWhenSolvedThenHuberKeepsTheSolutionClose) {
  // GIVEN the six TDoAs plus four more of the well-determined pairs, one of them off by 2 m
  std::vector<MultilaterationSample> s = handSamples();
  const std::vector<MultilaterationSample> again = handSamples();
  s.insert(s.end(), again.begin(), again.begin() + 4);
  s[3].z.tdoa_m += 2.0;
  // WHEN multilaterating with the default Huber threshold (0.3 m) and with plain least squares (huge threshold)
  const auto robust = multilaterate(s, handAnchors(), Vec3::Zero(), {Vec3(0, 0, 2)});
  const auto plain = multilaterate(s, handAnchors(), Vec3::Zero(), {Vec3(0, 0, 2)}, 1e6);
  // THEN the robust solution is closer to the tag than the least-squares one
  ASSERT_TRUE(robust && plain);
  EXPECT_LT((robust->w_p0 - Vec3(0, 0, 1)).norm(), (plain->w_p0 - Vec3(0, 0, 1)).norm());
}

TEST(Multilaterate, GivenTooFewUsableSamplesThenNoSolution) {
  // GIVEN three samples, or six whose anchors are missing from the table but three
  const std::vector<MultilaterationSample> all = handSamples();
  const std::vector<MultilaterationSample> three(all.begin(), all.begin() + 3);
  AnchorTable partial;
  partial.set(0, Vec3(3, 4, 1));
  partial.set(1, Vec3(-4, 3, 1));
  partial.set(2, Vec3(0, 0, 4));
  // THEN there is no solution (fewer than 4 usable samples), nor without any start
  EXPECT_FALSE(multilaterate(three, handAnchors(), Vec3::Zero(), {Vec3(0, 0, 2)}));
  EXPECT_FALSE(multilaterate(all, partial, Vec3::Zero(), {Vec3(0, 0, 2)}));  // only (0,1), (1,2), (0,2) usable
  EXPECT_FALSE(multilaterate(all, handAnchors(), Vec3::Zero(), {}));
}

TEST(Multilaterate, GivenTwoStartsWhenOneIsBadThenTheLowerCostSolutionWins) {
  // GIVEN a good start and one far outside the anchors
  const auto res = multilaterate(handSamples(), handAnchors(), Vec3::Zero(), {Vec3(50, 50, -50), Vec3(0.5, 0.5, 1.5)});
  // THEN the returned solution is the tag
  ASSERT_TRUE(res);
  EXPECT_LT((res->w_p0 - Vec3(0, 0, 1)).norm(), 1e-9);
}

}  // namespace
}  // namespace uwb
