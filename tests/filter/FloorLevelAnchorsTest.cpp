/** @file FloorLevelAnchorsTest.cpp
 *  @brief Floor-level anchors and their delays on the floor (docs/math/filter.md F16f).
 */
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "uwb/filter/FloorLevelAnchors.h"

namespace uwb {
namespace {

AnchorTable mixedRoom() {
  AnchorTable t;
  t.set(0, Vec3(-3, -4, 0.2));
  t.set(1, Vec3(-3, 4, 2.9));
  t.set(2, Vec3(3, 4, 0.17));
  t.set(3, Vec3(4, -4, 3.2));
  t.set(5, Vec3(4, -3, 1.05));  // just above the default 1 m
  return t;
}

TEST(FloorLevelAnchors, GivenAnchorHeightsWhenClassifiedThenOnlyThoseBelowTheHeightAboveTheFloorAreFloorLevel) {
  const FloorLevelAnchors f(mixedRoom(), 0.0, 1.0);
  EXPECT_TRUE(f.any());
  EXPECT_TRUE(f.isFloorLevel(0));
  EXPECT_FALSE(f.isFloorLevel(1));
  EXPECT_TRUE(f.isFloorLevel(2));
  EXPECT_FALSE(f.isFloorLevel(3));
  EXPECT_FALSE(f.isFloorLevel(4));  // unknown id
  EXPECT_FALSE(f.isFloorLevel(5));
  EXPECT_FALSE(f.isFloorLevel(-1));
  // the height counts from the floor: with the floor at 0.1 m, 1.05 m is 0.95 m above it
  EXPECT_TRUE(FloorLevelAnchors(mixedRoom(), 0.1, 1.0).isFloorLevel(5));
  // 0 turns it off
  EXPECT_FALSE(FloorLevelAnchors(mixedRoom(), 0.0, 0.0).any());
}

TEST(FloorLevelAnchors, GivenDelaysWhenAPairIsCorrectedThenItIsTheDelayOfBMinusTheDelayOfA) {
  FloorLevelAnchors f(mixedRoom(), 0.0, 1.0);
  EXPECT_FALSE(f.hasDelays());
  EXPECT_EQ(f.pairDelay(0, 1), 0.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // anchor 0 late by 2.9 m, anchor 2 not found (NaN), an entry for the high anchor 1 that must be ignored
  f.setDelays({2.9, 5.0, nan});
  EXPECT_TRUE(f.hasDelays());
  EXPECT_DOUBLE_EQ(f.delay(0), 2.9);
  EXPECT_EQ(f.delay(1), 0.0);
  EXPECT_EQ(f.delay(2), 0.0);
  // z = ‖p − a_B‖ − ‖p − a_A‖: a late A shortens the TDoA, a late B lengthens it
  EXPECT_DOUBLE_EQ(f.pairDelay(0, 1), -2.9);
  EXPECT_DOUBLE_EQ(f.pairDelay(1, 0), 2.9);
  EXPECT_EQ(f.pairDelay(1, 3), 0.0);
  EXPECT_EQ(f.pairDelay(7, 9), 0.0);  // unknown ids
  // a later fix replaces the delays; one without any finite delay clears them
  f.setDelays({nan, nan, 3.1});
  EXPECT_EQ(f.delay(0), 0.0);
  EXPECT_DOUBLE_EQ(f.pairDelay(2, 0), -3.1);
  f.setDelays({});
  EXPECT_FALSE(f.hasDelays());
}

TEST(FloorLevelAnchors, GivenAResidualThenTheDelayIsTakenWhenTheResidualLiesNearerToItThanToZero) {
  FloorLevelAnchors f(mixedRoom(), 0.0, 1.0);
  // no delays known: nothing to take, whatever the residual
  EXPECT_EQ(f.nearerPairDelay(0, 1, -3.0), 0.0);
  f.setDelays({2.9});
  // pair (0, 1): g_1 − g_0 = −2.9 m; a residual near −2.9 m is the floor's, one near 0 is a TDoA seen from the air
  EXPECT_DOUBLE_EQ(f.nearerPairDelay(0, 1, -2.7), -2.9);
  EXPECT_DOUBLE_EQ(f.nearerPairDelay(0, 1, -3.5), -2.9);
  EXPECT_EQ(f.nearerPairDelay(0, 1, -0.4), 0.0);
  EXPECT_EQ(f.nearerPairDelay(0, 1, 2.9), 0.0);  // the wrong sign is never the floor's
  // the decision boundary is the midpoint, −1.45 m
  EXPECT_DOUBLE_EQ(f.nearerPairDelay(0, 1, -1.46), -2.9);
  EXPECT_EQ(f.nearerPairDelay(0, 1, -1.44), 0.0);
  // the reversed pair has the reversed sign; a pair of two high anchors carries no delay
  EXPECT_DOUBLE_EQ(f.nearerPairDelay(1, 0, 2.5), 2.9);
  EXPECT_EQ(f.nearerPairDelay(1, 3, 3.0), 0.0);
}

TEST(FloorLevelAnchors, GivenAHeightThenTheRemainingFractionFadesSmoothlyOverTheFadeHeight) {
  const double h = FloorLevelAnchors::kFadeHeight_m;
  EXPECT_EQ(FloorLevelAnchors::remainingFraction(0.0), 1.0);
  EXPECT_EQ(FloorLevelAnchors::remainingFraction(-0.05), 1.0);  // below the resting height: all of it
  EXPECT_NEAR(FloorLevelAnchors::remainingFraction(0.5 * h), 0.5, 1e-15);
  EXPECT_NEAR(FloorLevelAnchors::remainingFraction(0.25 * h), 1.0 - (3.0 * 0.0625 - 2.0 * 0.015625), 1e-15);
  EXPECT_EQ(FloorLevelAnchors::remainingFraction(h), 0.0);
  EXPECT_EQ(FloorLevelAnchors::remainingFraction(2.0), 0.0);
}

TEST(ClimbFromFloor, GivenAConstantUpwardAccelerationThenTheHeightIsHalfATSquaredUntilTheFadeHeight) {
  // GIVEN a body leaving the floor at t = 10 s with a_up = 1 m/s², IMU at 1 kHz
  ClimbFromFloor c;
  c.start(10.0);
  const double dt = 1e-3;
  double t = 10.0;
  // WHEN integrating 0.3 s, THEN h = ½ a t² (exact for constant a), still below the fade height
  for (int k = 0; k < 300; ++k) c.integrate(t += dt, 1.0, dt);
  EXPECT_TRUE(c.running());
  EXPECT_NEAR(c.height(), 0.5 * 0.3 * 0.3, 1e-9);
  // and it ends once above the fade height (h = 0.12 m at t ≈ 0.49 s)
  for (int k = 0; k < 300 && c.running(); ++k) c.integrate(t += dt, 1.0, dt);
  EXPECT_FALSE(c.running());
  EXPECT_GT(c.height(), FloorLevelAnchors::kFadeHeight_m);
  EXPECT_LT(t - 10.0, 0.5);
}

TEST(ClimbFromFloor, GivenADownwardPushOnTheFloorThenItStaysOnTheFloorAndEndsAfterItsMaximumDuration) {
  // GIVEN a body on the floor whose vertical specific force reads below gravity (a_up < 0: bias, spin-up)
  ClimbFromFloor c;
  c.start(0.0);
  const double dt = 1e-3;
  double t = 0.0;
  for (int k = 0; k < 500; ++k) c.integrate(t += dt, -0.5, dt);
  // THEN the floor holds it (height 0, no downward velocity stored), and a later upward push starts from rest
  EXPECT_EQ(c.height(), 0.0);
  for (int k = 0; k < 100; ++k) c.integrate(t += dt, 1.0, dt);
  EXPECT_NEAR(c.height(), 0.5 * 0.1 * 0.1, 1e-9);
  // and it gives up after kMaxDuration_s: beyond that the accelerometer alone is not trusted
  while (t < ClimbFromFloor::kMaxDuration_s + 0.01) c.integrate(t += dt, 0.0, dt);
  EXPECT_FALSE(c.running());
  // clear() stops it at once
  c.start(t);
  c.clear();
  EXPECT_FALSE(c.running());
}

}  // namespace
}  // namespace uwb
