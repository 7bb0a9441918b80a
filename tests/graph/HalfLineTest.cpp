/** @file HalfLineTest.cpp
 *  @brief The half-line node (docs/math/message-passing.md G23): moments of a Gaussian truncated below against
 *         quadrature and high-precision reference values, and its message through the equality node.
 */
#include "uwb/graph/HalfLine.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace uwb {
namespace {

/// Mean and variance of N(m, v) restricted to x ≥ l by composite Simpson quadrature over [l, m + 14√v ∨ l + 14√v].
TruncatedMoments quadrature(double m, double v, double l) {
  const double sd = std::sqrt(v);
  const double hi = std::max(m, l) + 14.0 * sd;
  const int n = 200000;  // even
  const double h = (hi - l) / n;
  double z0 = 0.0, z1 = 0.0, z2 = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double x = l + i * h;
    const double w = (i == 0 || i == n) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
    const double p = std::exp(-0.5 * (x - m) * (x - m) / v);
    z0 += w * p;
    z1 += w * p * x;
    z2 += w * p * x * x;
  }
  const double mean = z1 / z0;
  return {mean, z2 / z0 - mean * mean};
}

TEST(HalfLine, MomentsAreThoseOfTheTruncatedDensity) {
  // GIVEN beliefs with the bound from far below their mean to several σ above it
  for (double a : {-4.0, -1.5, -0.3, 0.0, 0.06, 0.7, 1.0, 2.5, 4.0, 6.0}) {
    SCOPED_TRACE("a = " + std::to_string(a));
    const double m = 0.4, v = 0.81, l = m + a * std::sqrt(v);
    // WHEN the moments are computed in closed form (G23a)
    const TruncatedMoments t = truncatedBelow(m, v, l);
    // THEN they equal the quadrature of the truncated density
    const TruncatedMoments q = quadrature(m, v, l);
    EXPECT_NEAR(t.mean, q.mean, 1e-9);
    EXPECT_NEAR(t.var, q.var, 1e-9 * v);
    EXPECT_GE(t.mean, l);
    EXPECT_LT(t.var, v);
  }
}

TEST(HalfLine, TheFarTailMatchesHighPrecisionValues) {
  // GIVEN λ − a and 1 − δ of the standard normal truncated at a, computed with 60-digit arithmetic (mpmath)
  struct Ref {
    double a, gap, one_minus_delta;
  };
  const Ref refs[] = {{2.9, 0.29031513954298199, 0.073803215077491113},
                      {3.0, 0.28309865493043651, 0.070559186785268117},
                      {5.0, 0.18650396712584212, 0.032696434617112225},
                      {10.0, 0.098093233962511963, 0.0094453778256562612},
                      {20.0, 0.049753068527850542, 0.0024632616150521636},
                      {30.0, 0.033259667433677037, 0.001103771511890091},
                      {31.0, 0.032191276777724727, 0.0010341415899533916},
                      {40.0, 0.024968847207263723, 0.00062266837859138877},
                      {100.0, 0.0099980009992607052, 9.994004994826345e-5},
                      {1e5, 9.999999998e-6, 9.999999994e-11}};
  for (const Ref& r : refs) {
    SCOPED_TRACE("a = " + std::to_string(r.a));
    // WHEN N(−a, 1) is truncated at 0 (either side of the switch to the continued fraction at a = 3)
    const TruncatedMoments t = truncatedBelow(-r.a, 1.0, 0.0);
    // THEN the mean is λ − a and the variance 1 − δ, to a relative 1e-12
    EXPECT_NEAR(t.mean / r.gap, 1.0, 1e-12);
    EXPECT_NEAR(t.var / r.one_minus_delta, 1.0, 1e-12);
  }
  // and no mass below the bound leaves the belief as it was
  const TruncatedMoments far = truncatedBelow(2.0, 0.25, -100.0);
  EXPECT_DOUBLE_EQ(far.mean, 2.0);
  EXPECT_DOUBLE_EQ(far.var, 0.25);
}

TEST(HalfLine, TheMessageThroughTheEqualityNodeGivesTheTruncatedMoments) {
  for (double a : {-2.0, 0.0, 0.5, 3.0, 12.0, 45.0}) {
    SCOPED_TRACE("a = " + std::to_string(a));
    // GIVEN a belief N(m, v) and a bound a standard deviations from its mean
    const double m = -0.05, v = 0.7, l = m + a * std::sqrt(v);
    // WHEN the half-line node's message (G23b) is combined with the belief in the equality node (G5)
    const auto msg = halfLineMessage(m, v, l);
    ASSERT_TRUE(msg.has_value());
    ASSERT_GT(msg->var, 0.0);
    const double k = v / (v + msg->var);
    const double mean = m + k * (msg->y - m), var = v * msg->var / (v + msg->var);
    // THEN the result is the belief truncated to x ≥ l
    const TruncatedMoments t = truncatedBelow(m, v, l);
    EXPECT_NEAR(mean, t.mean, 1e-12 * (1.0 + std::abs(t.mean)));
    EXPECT_NEAR(var / t.var, 1.0, 1e-9);
  }
  // a belief with no mass below the bound gets no message
  EXPECT_FALSE(halfLineMessage(0.0, 1.0, -7.0).has_value());
}

TEST(HalfLine, RejectsBadInput) {
  EXPECT_THROW(truncatedBelow(0.0, 0.0, 0.0), std::invalid_argument);
  EXPECT_THROW(truncatedBelow(0.0, -1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(truncatedBelow(std::nan(""), 1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(halfLineMessage(0.0, 1.0, INFINITY), std::invalid_argument);
}

}  // namespace
}  // namespace uwb
