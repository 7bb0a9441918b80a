/** @file GaussianMessageTest.cpp
 *  @brief Moment ↔ information conversions (docs/math/message-passing.md G1–G2).
 */
#include "uwb/graph/GaussianMessage.h"

#include <gtest/gtest.h>

#include "GraphTestUtil.h"

namespace uwb {
namespace {

using namespace graphtest;

TEST(GaussianMessage, MomentsInformationRoundTrip) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    // GIVEN random moments of dimension 1…6
    std::mt19937 rng(seed);
    const Moments x = randomMoments(rng, 1 + seed % 6);
    // WHEN we convert to information form and back
    const auto info = toInformation(x);
    ASSERT_TRUE(info);
    const auto back = toMoments(*info);
    ASSERT_TRUE(back);
    // THEN ξ = W m, W V = I, and the round trip is the identity
    EXPECT_LT(maxAbs(info->W * x.V - MatX::Identity(x.m.size(), x.m.size())), 1e-10);
    EXPECT_LT(maxAbs(info->xi - info->W * x.m), 1e-10);
    EXPECT_LT(maxAbsDifference(*back, x), 1e-10);
  }
}

TEST(GaussianMessage, VariantConvertsOnRequest) {
  // GIVEN a message held as information in a variant
  std::mt19937 rng(3);
  const Moments x = randomMoments(rng, 3);
  const GaussianMessage msg = *toInformation(x);
  // WHEN we ask for both forms
  const auto as_m = asMoments(msg);
  const auto as_i = asInformation(msg);
  // THEN moments are converted and information is passed through unchanged
  ASSERT_TRUE(as_m && as_i);
  EXPECT_LT(maxAbs(as_m->m - x.m), 1e-10);
  EXPECT_EQ(as_i->W, std::get<Information>(msg).W);
}

TEST(GaussianMessage, SingularInformationHasNoMomentForm) {
  // GIVEN a rank-one information matrix (one scalar measurement of a 3-D position)
  const Vec3 b(0.6, 0.0, 0.8);
  Mat3 bbT;  // b bᵀ entry by entry: GCC 12 reads the Eigen outer product of a Vec3 with a 4-wide AVX load (a
             // -Warray-bounds false positive)
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) bbT(r, c) = b(r) * b(c);
  const Information info{b * 2.0, bbT};
  // WHEN we ask for moments, THEN the conversion refuses rather than returning Inf/NaN
  EXPECT_FALSE(toMoments(info));
  const Moments zero_var{VecX::Zero(2), MatX::Zero(2, 2)};
  EXPECT_FALSE(toInformation(zero_var));
}

}  // namespace
}  // namespace uwb
