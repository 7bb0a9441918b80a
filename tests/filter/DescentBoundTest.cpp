/** @file DescentBoundTest.cpp
 *  @brief The dead-reckoned descent bound (docs/math/filter.md F26).
 */
#include <gtest/gtest.h>

#include <cmath>

#include "uwb/filter/DescentBound.h"

namespace uwb {
namespace {

constexpr double kDt = 0.001;

/// Integrates a constant vertical acceleration for duration_s.
void fly(DescentBound& b, double a_up, double duration_s) {
  for (double t = 0.0; t < duration_s - 0.5 * kDt; t += kDt) b.integrate(a_up, kDt);
}

TEST(DescentBound, NoBoundBeforeTheEstimateWasHigh) {
  // GIVEN a fresh bound WHEN the estimate is low THEN there is no bound and no dead reckoning
  DescentBound b;
  EXPECT_TRUE(std::isnan(b.update(0.0, 0.2, 0.0)));
  EXPECT_FALSE(b.running());
  fly(b, -5.0, 1.0);
  EXPECT_TRUE(std::isnan(b.update(1.0, 0.1, 0.0)));
}

TEST(DescentBound, HighEstimateRestartsTheDeadReckoning) {
  // GIVEN an estimate 1.2 m high descending at 0.5 m/s
  DescentBound b;
  EXPECT_TRUE(std::isnan(b.update(0.0, 1.2, -0.5)));  // high: no bound
  ASSERT_TRUE(b.running());
  // WHEN 1 s passes without acceleration THEN the dead-reckoned height is 0.7 m (h + v t), still above the band
  fly(b, 0.0, 1.0);
  EXPECT_NEAR(b.height(), 0.7, 1e-9);
  EXPECT_TRUE(std::isnan(b.update(1.0, 0.9, -0.5)));  // 0.9 m: restarted from the estimate
  EXPECT_NEAR(b.height(), 0.9, 1e-12);
}

TEST(DescentBound, BoundsTheHeightAboveALowDeadReckoning) {
  // GIVEN a descent through the reset height, braked to rest at the floor: v = −1 m/s, a = +2 m/s² for 0.5 s
  DescentBoundParams p;
  DescentBound b(p);
  b.update(0.0, 0.8, -1.0);
  fly(b, 2.0, 0.5);
  // THEN the dead reckoning ends at h = 0.8 − 1·0.5 + ½·2·0.25 = 0.55 m, at rest
  EXPECT_NEAR(b.height(), 0.55, 1e-9);
  EXPECT_NEAR(b.verticalVelocity(), 0.0, 1e-9);
  EXPECT_TRUE(std::isnan(b.update(0.5, 0.6, 0.0)));  // 0.55 m is above the 0.4 m band: no bound
  // WHEN it keeps braking down to 0.3 m (a descent at 0.5 m/s for 0.5 s, then at rest)
  fly(b, -1.0, 0.5);   // v → −0.5 m/s, h → 0.425
  fly(b, 1.0, 0.5);    // v → 0, h → 0.30
  EXPECT_NEAR(b.height(), 0.30, 1e-9);
  // THEN an estimate that climbs away is bounded at the dead-reckoned height plus the margin, also above the reset
  // height: a high estimate restarts the dead reckoning only when that has left the band as well
  EXPECT_NEAR(b.update(1.5, 0.7, 0.8), 0.30 + p.margin_m, 1e-9);
  EXPECT_NEAR(b.update(1.6, 1.0, 0.8), 0.30 + p.margin_m, 1e-9);
}

TEST(DescentBound, ExpiresAndNeverSinksBelowTheFloor) {
  DescentBoundParams p;
  DescentBound b(p);
  b.update(0.0, 0.8, -2.0);
  // GIVEN a dead reckoning that would reach 0.8 − 2·1 = −1.2 m THEN it stops at the floor
  fly(b, 0.0, 1.0);
  EXPECT_EQ(b.height(), 0.0);
  EXPECT_GE(b.verticalVelocity(), 0.0);
  EXPECT_NEAR(b.update(1.0, 0.5, 0.0), p.margin_m, 1e-12);
  // WHEN more than max_age_s passed since the restart THEN there is no bound any more
  EXPECT_TRUE(std::isnan(b.update(p.max_age_s + 0.01, 0.5, 0.0)));
  // and clear() ends the dead reckoning
  b.update(0.0, 0.8, 0.0);
  b.clear();
  EXPECT_FALSE(b.running());
  EXPECT_TRUE(std::isnan(b.update(0.1, 0.5, 0.0)));
}

}  // namespace
}  // namespace uwb
